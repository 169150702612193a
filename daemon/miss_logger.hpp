#pragma once

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cstdint>
#include <string>

#include "rt/deadline_monitor.hpp"

namespace hapticsim {

// Collapses deadline misses into one line per burst: a burst ends after 200 ms without a miss.
class MissLogger {
 public:
  MissLogger(std::string thread, double max_lines_per_s)
      : thread_(std::move(thread)), min_gap_s_(1.0 / max_lines_per_s) {}

  void Add(const DeadlineEvent& event) {
    if (count_ == 0) first_ns_ = event.release_ns;
    ++count_;
    last_ns_ = event.release_ns;
    worst_lateness_ns_ = std::max(worst_lateness_ns_, event.lateness_ns);
    worst_execution_ns_ = std::max(worst_execution_ns_, event.execution_ns);
  }

  void Flush(std::int64_t now_ns, bool force = false) {
    if (count_ == 0) return;
    const bool quiet = now_ns - last_ns_ > 200'000'000;
    const bool allowed = (now_ns - last_line_ns_) * 1e-9 >= min_gap_s_;
    if (!(force || (quiet && allowed))) return;
    spdlog::warn(
        "deadline misses: {} thread, {} periods late over {:.1f} ms (worst wake-up "
        "lateness {:.0f} µs, worst compute {:.0f} µs)",
        thread_, count_, (last_ns_ - first_ns_) * 1e-6, worst_lateness_ns_ * 1e-3,
        worst_execution_ns_ * 1e-3);
    count_ = 0;
    worst_lateness_ns_ = worst_execution_ns_ = 0;
    last_line_ns_ = now_ns;
  }

 private:
  std::string thread_;
  double min_gap_s_;
  std::int64_t count_ = 0, first_ns_ = 0, last_ns_ = 0, last_line_ns_ = 0;
  std::int64_t worst_lateness_ns_ = 0, worst_execution_ns_ = 0;
};

}  // namespace hapticsim
