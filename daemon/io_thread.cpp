#include "daemon/io_thread.hpp"

#include <pthread.h>
#include <time.h>

namespace hapticsim {

IoThread::IoThread(HapticLoop& loop, const InputCounters& counters, LcmBridge* bridge,
                   ShmServer* shm)
    : loop_(loop), counters_(counters), bridge_(bridge), shm_(shm), alive_ns_(HapticLoop::NowNs()) {
  thread_ = std::thread([this] { Run(); });
}

void IoThread::Stop() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
}

void IoThread::Run() {
  pthread_setname_np(pthread_self(), "hsim-io");
  const timespec quarter_ms{0, 250'000}, one_ms{0, 1'000'000}, idle_wait{0, 20'000'000};
  ForceRecord record;
  std::int64_t inputs_seen = -1, last_input_ns = 0;
  while (!stop_.load()) {
    alive_ns_.store(HapticLoop::NowNs(), std::memory_order_relaxed);
    // An input handed over lately: its answer comes within a period or two (the primary may
    // still say idle until its next period runs), so poll fast for a while whatever it says.
    const std::int64_t inputs = counters_.inputs_received.load();
    const std::int64_t now = HapticLoop::NowNs();
    if (inputs != inputs_seen) last_input_ns = now;
    inputs_seen = inputs;
    const bool idle = loop_.idle() && now - last_input_ns > 5'000'000;
    const timespec& wait = !idle ? quarter_ms : shm_ ? one_ms : idle_wait;
    if (bridge_) {
      bridge_->Poll(wait);
    } else {
      nanosleep(&wait, nullptr);
    }
    if (shm_) shm_->PollInput();
    while (loop_.forces().Pop(&record)) {
      if (bridge_) bridge_->Publish(record);
      if (shm_) shm_->Publish(record);
    }
    if (bridge_) bridge_->PublishPendingStatus();
  }
}

}  // namespace hapticsim
