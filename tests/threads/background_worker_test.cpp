// The supervisor's one background thread: the newest request wins, a flood of requests makes no
// thread and leaves at most one job waiting, errors come back as outcomes, and destruction never
// waits for a long job.
#include "daemon/background_worker.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <fstream>
#include <string>
#include <thread>

#include "core/error.hpp"

namespace hapticsim {
namespace {

using Clock = std::chrono::steady_clock;

int ThreadsOfThisProcess() {
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);) {
    if (line.rfind("Threads:", 0) == 0) return std::stoi(line.substr(8));
  }
  return -1;
}

template <typename Result>
typename BackgroundWorker<Result>::Outcome WaitForOutcome(BackgroundWorker<Result>& worker) {
  const auto deadline = Clock::now() + std::chrono::seconds(10);
  while (Clock::now() < deadline) {
    if (auto outcome = worker.Take()) return *outcome;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  ADD_FAILURE() << "no outcome within 10 s";
  return {};
}

TEST(BackgroundWorker, AFloodOfRequestsMakesNoThreadAndTheNewestWins) {
  BackgroundWorker<int> worker("test-worker");
  const int threads = ThreadsOfThisProcess();
  std::atomic<int> ran{0};
  std::atomic<bool> release{false};
  worker.Submit([&ran, &release] {  // a long estimate, running until the flood is over
    ++ran;
    while (!release) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    return -1;
  });
  while (ran == 0) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  int most_threads = threads;
  for (int i = 0; i < 1000; ++i) {
    worker.Submit([&ran, i] {
      ++ran;
      return i;
    });
    EXPECT_TRUE(worker.busy());
    if (i % 100 == 0) most_threads = std::max(most_threads, ThreadsOfThisProcess());
  }
  release = true;
  const auto outcome = WaitForOutcome(worker);
  ASSERT_TRUE(outcome.result.has_value()) << outcome.error;
  EXPECT_EQ(*outcome.result, 999);  // the running job's −1 and 998 replaced jobs: dropped
  EXPECT_EQ(ran.load(), 2) << "the first, then only the newest of those that waited";
  EXPECT_EQ(most_threads, threads) << "a request made a thread";
  EXPECT_FALSE(worker.busy());
  EXPECT_FALSE(worker.Take().has_value()) << "an outcome is taken once";
}

TEST(BackgroundWorker, AnErrorIsAnOutcomeAndTheWorkerGoesOn) {
  BackgroundWorker<int> worker("test-worker");
  worker.Submit([]() -> int { throw Error("no stable configuration"); });
  const auto failed = WaitForOutcome(worker);
  EXPECT_FALSE(failed.result.has_value());
  EXPECT_EQ(failed.error, "no stable configuration");
  worker.Submit([] { return 7; });
  EXPECT_EQ(WaitForOutcome(worker).result, 7);
}

TEST(BackgroundWorker, DestructionDoesNotWaitForALongJob) {
  const auto start = Clock::now();
  {
    BackgroundWorker<int> worker("test-worker");
    worker.Submit([] {
      std::this_thread::sleep_for(std::chrono::seconds(5));  // a minute-long estimate, shorter
      return 0;
    });
    while (worker.running_since_ns() == 0) {  // the job has started (not just been queued)
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  }
  const double waited_s = std::chrono::duration<double>(Clock::now() - start).count();
  EXPECT_LT(waited_s, BackgroundWorker<int>::kJoinWait_s + 0.5);
  // The daemon is told, so that it leaves by _Exit instead of destroying statics the job reads.
  EXPECT_TRUE(AJobWasLeftRunning());
  // An idle worker is joined at once.
  const auto idle_start = Clock::now();
  { BackgroundWorker<int> idle("test-worker"); }
  EXPECT_LT(std::chrono::duration<double>(Clock::now() - idle_start).count(), 0.5);
}

}  // namespace
}  // namespace hapticsim
