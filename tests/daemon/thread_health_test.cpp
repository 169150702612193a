// The health check's verdicts (daemon/thread_health.hpp): which threads are stalled, in words,
// and whether the force depends on them.
#include "daemon/thread_health.hpp"

#include <gtest/gtest.h>

namespace hapticsim {
namespace {

constexpr std::int64_t kSecond = 1'000'000'000;

TEST(ThreadHealth, AThreadSilentLongerThanItMayBeIsStalledUnlessItIsMeantToBeIdle) {
  const std::int64_t now = 100 * kSecond;
  const std::vector<ThreadBeat> beats = {
      {"primary (hsim-primary)", now - kSecond / 20, 0.1, true, true},     // 50 ms: fine
      {"I/O (hsim-io)", now - 2 * kSecond, 0.5, true, true},               // 2 s: stalled
      {"secondary (hsim-region1)", now - 3 * kSecond, 0.5, false, false},  // asleep: idle
      {"secondary 2 (hsim-region2)", now - kSecond, 0.5, true, false},  // stalled, rendered around
      {"hsim-choose", now - 10 * kSecond, 300, true, false},            // a job of 10 s: fine
  };
  const std::vector<Stall> stalls = StalledThreads(beats, now);
  ASSERT_EQ(stalls.size(), 2u);
  EXPECT_EQ(DescribeStalls(stalls), "I/O (hsim-io) (2.0 s), secondary 2 (hsim-region2) (1.0 s)");
  EXPECT_TRUE(AnyOnForcePath(stalls));  // the I/O thread: no force reaches the device
  EXPECT_FALSE(AnyOnForcePath({stalls[1]}));
  EXPECT_EQ(DescribeStalls({}), "");
  // At the limit it is not yet a stall; just beyond, it is.
  EXPECT_TRUE(StalledThreads({{"x", now - kSecond / 2, 0.5, true, true}}, now).empty());
  EXPECT_EQ(StalledThreads({{"x", now - kSecond / 2 - 1000, 0.5, true, true}}, now).size(), 1u);
}

}  // namespace
}  // namespace hapticsim
