#pragma once

#include <time.h>

#include <algorithm>
#include <atomic>
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

/**
 * Sleeps until an absolute CLOCK_MONOTONIC time, or until `stop` is set: it looks at `stop` at
 * least every `slice_ns`, so a thread asked to stop is never held by a wake far ahead (one that
 * joins it — a reconfiguration replacing the secondary threads — waits a slice at most). The
 * last slice ends at `wake_ns` exactly. False when it stopped early.
 */
inline bool SleepUntilMonotonicNsOrStop(std::int64_t wake_ns, const std::atomic<bool>& stop,
                                        std::int64_t slice_ns = 10'000'000) noexcept {
  for (;;) {
    if (stop.load(std::memory_order_acquire)) return false;
    const std::int64_t now = MonotonicNowNs();
    if (now >= wake_ns) return true;
    SleepUntilMonotonicNs(std::min(wake_ns, now + slice_ns));
  }
}

}  // namespace hapticsim
