#pragma once
// Waits and wakes on an atomic word for hapticsimd's loop threads (daemon/haptic_loop*.cpp).

#include <linux/futex.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <atomic>
#include <climits>
#include <cstdint>
#include <ctime>

namespace hapticsim {

// The futex behind an atomic word, for every wait of the loop's threads: std::atomic::wait has
// no timeout (an idle primary must still come round now and then: stop, reconfiguration, the
// watchdog's sign of life), and a wake is one system call, no lock, in the 1 kHz path too.
static_assert(sizeof(std::atomic<std::uint32_t>) == sizeof(std::uint32_t) &&
              std::atomic<std::uint32_t>::is_always_lock_free);
inline void FutexWait(std::atomic<std::uint32_t>* word, std::uint32_t expected, double timeout_s) {
  const auto ns = static_cast<long>(timeout_s * 1e9);
  const timespec timeout{ns / 1'000'000'000, ns % 1'000'000'000};
  // Returns at once if *word != expected; spurious returns are harmless to the caller.
  syscall(SYS_futex, reinterpret_cast<std::uint32_t*>(word), FUTEX_WAIT_PRIVATE, expected, &timeout,
          nullptr, 0);
}
inline void FutexWakeAll(std::atomic<std::uint32_t>* word) {
  syscall(SYS_futex, reinterpret_cast<std::uint32_t*>(word), FUTEX_WAKE_PRIVATE, INT_MAX, nullptr,
          nullptr, 0);
}

}  // namespace hapticsim
