#pragma once
// Which of a loop's answers come from a primary period woken late, or from the few periods after
// one. On a shared machine a period now and then wakes a few milliseconds late and the next ones
// run back to back: the secondary regions' boundary is then older than the schedule says and the
// force steps (what that does is RealTimeSchedule's and SecondaryStall's to test). A test of how
// smooth something else is — a ramp, a re-centring — measures the periods woken on time, and
// checks that they are nearly all of them.

#include <algorithm>
#include <cstdint>
#include <vector>

namespace hapticsim {

struct Wake {
  std::int64_t period = 0;    // the primary period, counting every one
  std::int64_t utime_us = 0;  // when it ran
};

/**
 * For each answer: true if its period, or one of the `after` periods before it, woke more than
 * `late_us` later than the earliest-woken period of the run says it should have.
 */
inline std::vector<bool> NearALateWake(const std::vector<Wake>& wakes, double period_us = 1000,
                                       double late_us = 250, std::int64_t after = 3) {
  std::vector<bool> near(wakes.size(), false);
  if (wakes.empty()) return near;
  double earliest = 1e300;  // utime − period · period_us: the release grid's origin, or later
  for (const Wake& w : wakes) {
    earliest = std::min(
        earliest, static_cast<double>(w.utime_us) - static_cast<double>(w.period) * period_us);
  }
  std::int64_t last_late_period = -1'000'000;
  for (size_t i = 0; i < wakes.size(); ++i) {
    const double lateness = static_cast<double>(wakes[i].utime_us) -
                            static_cast<double>(wakes[i].period) * period_us - earliest;
    if (lateness > late_us) last_late_period = wakes[i].period;
    near[i] = wakes[i].period - last_late_period <= after;
  }
  return near;
}

}  // namespace hapticsim
