#pragma once
// Threads beside the real-time ones that must not compete with them for the CPU.

#include <errno.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

namespace hapticsim {

/** The niceness a thread off the force path takes (BackOffFromRealTimeThreads). */
inline constexpr int kBackgroundNice = 10;

/**
 * Lowers the calling thread's CPU priority to nice kBackgroundNice (or leaves it where it is, if
 * the process already runs nicer), so that where the CPUs are short the scheduler runs the region
 * threads (the process's own nice, or SCHED_FIFO where allowed) before it: a thread whose
 * lateness costs nothing but a late frame. Lowering one's own priority needs no privilege.
 * Linux: a thread's nice value is its own (setpriority on its thread id). Returns false if
 * refused (nothing changed).
 */
inline bool BackOffFromRealTimeThreads() noexcept {
  const auto tid = static_cast<id_t>(syscall(SYS_gettid));
  errno = 0;
  const int now = getpriority(PRIO_PROCESS, tid);
  if (errno != 0) return false;
  return now >= kBackgroundNice || setpriority(PRIO_PROCESS, tid, kBackgroundNice) == 0;
}

}  // namespace hapticsim
