#pragma once

#include <atomic>
#include <cstdint>
#include <thread>

#include "daemon/haptic_loop.hpp"
#include "daemon/input_counters.hpp"
#include "daemon/lcm_bridge.hpp"
#include "daemon/shm_server.hpp"

namespace hapticsim {

/**
 * The I/O thread ("hsim-io"): everything on the way between the device and the primary thread
 * that may block — LCM's receive and publish, the shared-memory input poll and its force rings —
 * at most 0.25 ms behind the primary thread. While the loop is idle (regions asleep, no device)
 * nothing needs it that often: LCM input wakes the poll anyway, so it waits up to 20 ms;
 * shared-memory input cannot wake it and is polled every millisecond.
 */
class IoThread {
 public:
  /** Starts the thread. `bridge` and `shm` may be null (that transport is off); what is given
   *  must outlive this. */
  IoThread(HapticLoop& loop, const InputCounters& counters, LcmBridge* bridge, ShmServer* shm);
  ~IoThread() { Stop(); }
  IoThread(const IoThread&) = delete;
  IoThread& operator=(const IoThread&) = delete;

  /** Ends the thread after its current poll, and waits for it. */
  void Stop();
  /** Its newest sign of life (CLOCK_MONOTONIC ns): the health check's beat. */
  std::int64_t alive_ns() const { return alive_ns_.load(std::memory_order_relaxed); }

 private:
  void Run();

  HapticLoop& loop_;
  const InputCounters& counters_;
  LcmBridge* bridge_;
  ShmServer* shm_;
  std::atomic<bool> stop_{false};
  std::atomic<std::int64_t> alive_ns_;
  std::thread thread_;
};

}  // namespace hapticsim
