#pragma once

#include <pthread.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <utility>

namespace hapticsim {

/**
 * One long-lived thread for the supervisor's slow work — choosing a configuration, verifying
 * one around a node: seconds of stability estimates that its tick must never wait for. The thread
 * is made once, at start, so no command can make another (a flood of commands once raised the
 * daemon's threads from 6 to 28, made its primary late in 733 periods, and aborted it when a
 * thread could not be made).
 *
 * Only the newest request matters: a job submitted while another waits replaces it; one
 * submitted while another runs waits for it; and the outcome of a job a newer one was submitted
 * after is dropped. So a flood leaves at most one job running and one waiting.
 *
 * At destruction the thread is asked to stop and joined; a job still running after
 * kJoinWait_s (an estimate can take a minute) is left to the process's exit, so that shutdown
 * never waits for it. Jobs must therefore own everything they touch (capture by value). A job
 * so left may still read statics (the scene's key table), so the process must then end without
 * destroying them: AJobWasLeftRunning() tells main to leave by std::_Exit. (Not yet: cancelling
 * a running estimate.)
 *
 * Submit and Take are for one thread (the supervisor's); they take a mutex the worker holds only
 * to hand jobs and outcomes over.
 */
/** Whether a BackgroundWorker was destroyed with its job still running (see below). */
inline std::atomic<bool>& JobLeftRunningFlag() {
  static std::atomic<bool> left{false};  // trivially destructible: safe to read at exit
  return left;
}
inline bool AJobWasLeftRunning() { return JobLeftRunningFlag().load(); }

template <typename Result>
class BackgroundWorker {
 public:
  /** A job's outcome: its result, or the message of the exception it threw. */
  struct Outcome {
    std::optional<Result> result;
    std::string error;
  };

  static constexpr double kJoinWait_s = 1.0;

  explicit BackgroundWorker(const std::string& thread_name) : state_(std::make_shared<State>()) {
    thread_ = std::thread([state = state_] { Run(*state); });
    pthread_setname_np(thread_.native_handle(), thread_name.substr(0, 15).c_str());
  }

  /** Asks the thread to stop after the job it runs (if any); the destructor then waits less. */
  void RequestStop() {
    std::lock_guard lock(state_->mutex);
    state_->stop = true;
    state_->wake.notify_all();
  }

  ~BackgroundWorker() {
    std::unique_lock lock(state_->mutex);
    state_->stop = true;
    state_->wake.notify_all();
    const bool finished = state_->wake.wait_for(lock, std::chrono::duration<double>(kJoinWait_s),
                                                [this] { return state_->exited; });
    lock.unlock();
    if (finished) {
      thread_.join();
    } else {
      thread_.detach();  // the shared state outlives us; the process's exit ends the job
      JobLeftRunningFlag().store(true);
    }
  }

  BackgroundWorker(const BackgroundWorker&) = delete;
  BackgroundWorker& operator=(const BackgroundWorker&) = delete;

  /** Queues `job`, replacing one that has not started. */
  void Submit(std::function<Result()> job) {
    std::lock_guard lock(state_->mutex);
    state_->job = std::move(job);
    state_->submitted += 1;
    state_->outcome.reset();  // an older job's outcome is no longer wanted
    state_->wake.notify_all();
  }

  /** True from Submit until Take has returned the newest job's outcome. */
  bool busy() const {
    std::lock_guard lock(state_->mutex);
    return state_->taken < state_->submitted;
  }

  /**
   * When the job running now started (CLOCK_MONOTONIC ns), or 0 when none runs: the health
   * check's sign of a job that never ends.
   */
  std::int64_t running_since_ns() const {
    return state_->running_since_ns.load(std::memory_order_relaxed);
  }

  /** The newest job's outcome, once (nothing while it waits or runs). */
  std::optional<Outcome> Take() {
    std::lock_guard lock(state_->mutex);
    if (!state_->outcome) return std::nullopt;
    state_->taken = state_->submitted;
    return std::exchange(state_->outcome, std::nullopt);
  }

 private:
  struct State {
    std::mutex mutex;
    std::condition_variable wake;
    std::function<Result()> job;     // waiting to run
    std::uint64_t submitted = 0;     // jobs submitted
    std::uint64_t taken = 0;         // the `submitted` count at the last outcome taken
    std::optional<Outcome> outcome;  // the newest job's, when it is done
    bool stop = false, exited = false;
    std::atomic<std::int64_t> running_since_ns{0};
  };

  static std::int64_t NowNs() {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(
               std::chrono::steady_clock::now().time_since_epoch())
        .count();
  }

  static void Run(State& state) {
    std::unique_lock lock(state.mutex);
    while (true) {
      state.wake.wait(lock, [&] { return state.stop || state.job; });
      if (state.stop) break;
      std::function<Result()> job = std::exchange(state.job, nullptr);
      const std::uint64_t generation = state.submitted;
      lock.unlock();
      state.running_since_ns.store(NowNs(), std::memory_order_relaxed);
      Outcome outcome;
      try {
        outcome.result = job();
      } catch (const std::exception& e) {
        outcome.error = e.what();
      } catch (...) {
        outcome.error = "an exception of unknown type";
      }
      job = nullptr;  // its captures (a scene, maybe a map's last reference) freed unlocked
      state.running_since_ns.store(0, std::memory_order_relaxed);
      lock.lock();
      if (generation == state.submitted) state.outcome = std::move(outcome);
    }
    state.exited = true;
    state.wake.notify_all();
  }

  std::shared_ptr<State> state_;
  std::thread thread_;
};

}  // namespace hapticsim
