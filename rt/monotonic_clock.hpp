#pragma once

#include <time.h>

#include <cerrno>
#include <cstdint>

namespace hapticsim {

/** CLOCK_MONOTONIC in ns: the one clock every periodic loop and every time stamp uses. */
inline std::int64_t MonotonicNowNs() noexcept {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

/** Sleeps until an absolute CLOCK_MONOTONIC time (a signal does not cut it short). */
inline void SleepUntilMonotonicNs(std::int64_t wake_ns) noexcept {
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(wake_ns / 1'000'000'000);
  ts.tv_nsec = static_cast<long>(wake_ns % 1'000'000'000);
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
}

}  // namespace hapticsim
