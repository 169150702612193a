#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "device/device_session.hpp"

namespace hapticsim::cli {

/** The device's limits (`--max-*`); a negative value is no limit. */
struct DeviceLimits {
  double p99_us = -1;
  double max_latency_us = -1;
  double unanswered = -1;
  double late_percent = -1;
  double lost = -1;
  double force_step_n = -1;
};

/** The names of the limits a report exceeds (empty: all met). */
std::vector<std::string> ExceededLimits(const device::SessionReport& report,
                                        const DeviceLimits& limits);

/** The report as JSON (keys carry their unit). */
nlohmann::json ReportJson(const device::SessionReport& report);

/** The report for people: one labelled line per number, with units. */
std::string ReportText(const device::SessionReport& report);

/** "in contact, input stale" from FLAG_* bits. */
std::string FlagNames(std::int32_t flags);

}  // namespace hapticsim::cli
