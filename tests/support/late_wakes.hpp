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
  std::int64_t period = 0;    // the primary period, counting every one answered
  std::int64_t utime_us = 0;  // when it ran
  // Answered on stale input: the loop may have idled waiting for input, and an idle loop goes
  // back on its release grid at the next release after the input came (HapticLoop::PrimaryThread),
  // so the periods counted no longer say when the next answers are due.
  bool input_stale = false;
};

/**
 * For each answer: true if its period, or one of the `after` periods before it, woke more than
 * `late_us` later than the earliest-woken period of its stretch says it should have. A stretch is
 * a run of answers to fresh input, over which the release grid stays put; answers to stale input
 * are never counted near a late wake (a test that measures steps across them counts those as on
 * time).
 */
inline std::vector<bool> NearALateWake(const std::vector<Wake>& wakes, double period_us = 1000,
                                       double late_us = 250, std::int64_t after = 3) {
  std::vector<bool> near(wakes.size(), false);
  auto offset = [&](const Wake& w) {  // utime − period · period_us: the grid's origin, or later
    return static_cast<double>(w.utime_us) - static_cast<double>(w.period) * period_us;
  };
  size_t begin = 0;
  while (begin < wakes.size()) {
    if (wakes[begin].input_stale) {
      ++begin;
      continue;
    }
    size_t end = begin;
    double earliest = 1e300;
    for (; end < wakes.size() && !wakes[end].input_stale; ++end) {
      earliest = std::min(earliest, offset(wakes[end]));
    }
    std::int64_t last_late_period = -1'000'000;
    for (size_t i = begin; i < end; ++i) {
      if (offset(wakes[i]) - earliest > late_us) last_late_period = wakes[i].period;
      near[i] = wakes[i].period - last_late_period <= after;
    }
    begin = end;
  }
  return near;
}

}  // namespace hapticsim
