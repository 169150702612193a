#include "core/errormap/parallel_for.hpp"

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace hapticsim {

void ParallelFor(std::size_t n, int jobs, const std::atomic<bool>* stop,
                 const std::function<void(std::size_t)>& fn, const std::function<void()>& tick,
                 double tick_interval_s) {
  std::atomic<std::size_t> next{0};
  std::atomic<bool> failed{false};
  std::exception_ptr error;
  std::mutex mutex;
  std::condition_variable done_cv;
  int running = std::max(1, jobs);
  std::vector<std::thread> workers;
  for (int j = 0; j < std::max(1, jobs); ++j) {
    workers.emplace_back([&] {
      for (;;) {
        if (failed || (stop && stop->load())) break;
        const std::size_t i = next.fetch_add(1);
        if (i >= n) break;
        try {
          fn(i);
        } catch (...) {
          std::lock_guard lock(mutex);
          if (!error) error = std::current_exception();
          failed = true;
        }
      }
      std::lock_guard lock(mutex);
      --running;
      done_cv.notify_all();
    });
  }
  {
    std::unique_lock lock(mutex);
    while (running > 0) {
      done_cv.wait_for(lock, std::chrono::duration<double>(tick_interval_s));
      lock.unlock();
      if (tick) tick();
      lock.lock();
    }
  }
  for (auto& worker : workers) worker.join();
  if (error) std::rethrow_exception(error);
}

}  // namespace hapticsim
