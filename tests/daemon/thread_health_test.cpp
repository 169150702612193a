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

// Said when the set of stalled threads changes and every 10 s while it lasts; once when it clears.
TEST(StallReport, SaysAChangeAtOnceARepeatEveryTenSecondsAndTheRecoveryOnce) {
  constexpr std::int64_t kSecond = 1'000'000'000;
  const std::vector<Stall> io{{"I/O (hsim-io)", 0.6, true}};
  const std::vector<Stall> both{{"I/O (hsim-io)", 1.6, true}, {"secondary", 0.7, false}};
  StallReport report;
  EXPECT_EQ(report.Due({}, 1 * kSecond), std::nullopt) << "nothing stalled, nothing to say";
  EXPECT_EQ(report.Due(io, 2 * kSecond), "I/O (hsim-io) (0.6 s)");
  EXPECT_EQ(report.Due(io, 3 * kSecond), std::nullopt);
  EXPECT_EQ(report.Due(both, 4 * kSecond), "I/O (hsim-io) (1.6 s), secondary (0.7 s)");
  EXPECT_EQ(report.Due(both, 14 * kSecond), std::nullopt) << "10 s is not yet more than 10 s";
  EXPECT_TRUE(report.Due(both, 14 * kSecond + 1).has_value());
  EXPECT_EQ(report.Due({}, 15 * kSecond), "") << "every thread runs again: said once";
  EXPECT_EQ(report.Due({}, 30 * kSecond), std::nullopt);
}

}  // namespace
}  // namespace hapticsim
