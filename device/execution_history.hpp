#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "hapticsim/status_t.hpp"

namespace hapticsim::device {

/**
 * One daemon thread's step compute time over a session, from its status messages. Each status
 * carries the median, 99th percentile and maximum of the last status interval (about 200 ms;
 * percentiles are the upper edges of 25 %-wide histogram bins); a session summary is the median
 * of those medians — what the thread's step usually costs — beside the worst interval's p99 and
 * the largest single step. The last status alone says only what the final 200 ms did.
 */
struct RegionExecution {
  std::string region;          ///< "primary", "secondary", …
  double rate_hz = 0;          ///< nominal rate, from the newest status
  std::int64_t intervals = 0;  ///< status intervals in which the thread stepped
  double p50_median_us = 0;    ///< median over intervals of the interval median, µs
  double p99_median_us = 0;    ///< median over intervals of the interval p99, µs
  double p99_worst_us = 0;     ///< largest interval p99, µs
  double max_us = 0;           ///< longest single step, µs
  /** p50_median_us as a share of the thread's nominal period (1 / rate_hz). */
  double p50_period_share() const { return p50_median_us * 1e-6 * rate_hz; }
};

/** Collects RegionExecution from status_t messages (one thread; the LCM link guards it). */
class ExecutionHistory {
 public:
  /** Adds one status; regions that did not step in its interval (asleep) are skipped. */
  void Add(const status_t& status);
  /** Per region name, in the order first seen. Regions of every configuration the session saw
   * are pooled by name. */
  std::vector<RegionExecution> Summary() const;

 private:
  struct Samples {
    double rate_hz = 0;
    std::vector<double> p50_us, p99_us;
    double max_us = 0;
  };
  std::vector<std::string> order_;
  std::map<std::string, Samples> samples_;
};

}  // namespace hapticsim::device
