#pragma once

#include <time.h>

#include <atomic>
#include <cstdint>
#include <thread>
#include <vector>

namespace hapticsim::device {

/**
 * Load as on a user's desktop, for as long as it lives: `threads` busy threads at normal priority
 * (no real-time privileges), each spinning on arithmetic. `hapticsim soak --cpu-load` and
 * `hapticsim device --cpu-load` run them beside the daemon to measure the force under load.
 *
 * Stop() says how much CPU time the threads were actually given, so a report (and a test) can
 * show the load was there rather than infer it from latencies that a noisy machine also moves.
 */
class CpuLoad {
 public:
  explicit CpuLoad(int threads) {
    for (int i = 0; i < threads; ++i) {
      threads_.emplace_back([this] {
        volatile double sink = 0;
        while (running_.load(std::memory_order_relaxed)) {
          for (int k = 0; k < 100000; ++k) sink = sink + 1e-9 * k;
        }
        timespec used{};
        clock_gettime(CLOCK_THREAD_CPUTIME_ID, &used);
        busy_ns_ += std::int64_t{used.tv_sec} * 1'000'000'000 + used.tv_nsec;
      });
    }
  }
  ~CpuLoad() { Stop(); }
  CpuLoad(const CpuLoad&) = delete;
  CpuLoad& operator=(const CpuLoad&) = delete;

  /** Ends the load (once; later calls return the same) and returns the CPU time it used, s. */
  double Stop() {
    running_ = false;
    for (std::thread& thread : threads_) {
      if (thread.joinable()) thread.join();
    }
    return static_cast<double>(busy_ns_.load()) * 1e-9;
  }

 private:
  std::atomic<bool> running_{true};
  std::atomic<std::int64_t> busy_ns_{0};
  std::vector<std::thread> threads_;
};

}  // namespace hapticsim::device
