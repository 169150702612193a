#pragma once

#include <atomic>
#include <thread>
#include <vector>

namespace hapticsim::device {

/**
 * Load as on a user's desktop, for as long as it lives: `threads` busy threads at normal priority
 * (no real-time privileges), each spinning on arithmetic. `hapticsim soak --cpu-load` and
 * `hapticsim device --cpu-load` run them beside the daemon to measure the force under load.
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
      });
    }
  }
  ~CpuLoad() {
    running_ = false;
    for (std::thread& thread : threads_) thread.join();
  }
  CpuLoad(const CpuLoad&) = delete;
  CpuLoad& operator=(const CpuLoad&) = delete;

 private:
  std::atomic<bool> running_{true};
  std::vector<std::thread> threads_;
};

}  // namespace hapticsim::device
