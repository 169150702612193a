#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace hapticsim {

/**
 * Deadlines before accuracy: tells the supervisor when a region keeps missing its deadlines —
 * more than `share` of its periods in each of `windows` consecutive one-second windows — so it
 * can choose a cheaper configuration. A single burst (a page fault, another process) does not
 * count; a configuration the machine cannot carry does. Supervisor thread only.
 */
class OverloadWatch {
 public:
  explicit OverloadWatch(double share = 0.05, int windows = 3) : share_(share), windows_(windows) {}

  /** `misses` more missed periods of `region` (as drained from its DeadlineMonitor). */
  void Count(int region, std::int64_t misses);
  /**
   * Closes a window when one has passed. Returns the region that has been over the share in every
   * one of the last `windows` windows (and starts counting afresh), else −1.
   * `rates_hz`: each region's periods per second.
   */
  int Check(std::int64_t now_ns, const std::vector<double>& rates_hz);
  /** Forgets everything: the regions were replaced. */
  void Reset(std::int64_t now_ns);

  /** Missed periods of the region found overloaded, in the last window. */
  std::int64_t last_misses() const { return last_misses_; }

 private:
  double share_;
  int windows_;
  std::int64_t window_end_ns_ = 0;
  std::vector<std::int64_t> misses_;  // in the open window, per region
  std::vector<int> over_;             // consecutive windows over the share, per region
  std::int64_t last_misses_ = 0;
};

/** The log line when a region overloaded second after second and the supervisor chooses a
 *  configuration cheaper than `cost_us_per_ms`. */
std::string ChoosingCheaperLine(const std::string& region, std::int64_t misses, double rate_hz,
                                double cost_us_per_ms);
/** … and when it cannot (`why`): what the user can do about it. */
std::string CannotChooseCheaperLine(const std::string& region, std::int64_t misses,
                                    const char* why);

}  // namespace hapticsim
