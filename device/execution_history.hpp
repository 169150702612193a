#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "hapticsim/status_t.hpp"

namespace hapticsim::device {

/**
 * One daemon thread's compute time per period over a session, from its status messages. Each
 * status carries the median, 99th percentile and maximum over its status interval (200 ms at the
 * default supervisor.status_rate_hz; the percentiles are upper edges of 25 %-wide histogram
 * bins); a session summary is the median of those medians — what a period usually costs — beside
 * the median and worst of the interval p99s and the longest period. The last status alone says
 * only what the final interval did.
 */
struct RegionExecution {
  std::string region;                 ///< "primary", "secondary", …
  double rate_hz = 0;                 ///< nominal rate, from the newest status
  std::int64_t intervals = 0;         ///< status intervals counted (awake, the thread stepping)
  double p50_median_us = 0;           ///< median over intervals of the interval median, µs
  double p50_period_share = 0;        ///< median over intervals of interval median × rate
  double p99_interval_median_us = 0;  ///< median over intervals of the interval p99, µs
  double p99_interval_worst_us = 0;   ///< largest interval p99, µs
  double max_us = 0;                  ///< longest single period, µs
};

/** Collects RegionExecution from status_t messages (one thread; the LCM link guards it). */
class ExecutionHistory {
 public:
  /** Adds one status. Skipped: a status of regions asleep (the primary then answers without
   * stepping, in microseconds), and a region that did not run in the interval. */
  void Add(const status_t& status);
  /** Per region name, in the order first seen. Regions of every configuration the session saw
   * are pooled by name. */
  std::vector<RegionExecution> Summary() const;

 private:
  struct Samples {
    std::string region;
    double rate_hz = 0;
    std::vector<double> p50_us, p50_share, p99_us;
    double max_us = 0;
  };
  std::vector<Samples> regions_;  // in the order first seen (a handful: a linear search)
};

}  // namespace hapticsim::device
