#include "core/realtime_schedule.hpp"

#include <gtest/gtest.h>

#include "core/force_error.hpp"

namespace hapticsim {
namespace {

Scene Adaptive(int primary_size, int lod, double rate_hz) {
  Scene scene;
  scene.adaptivity.primary_size = primary_size;
  scene.adaptivity.secondary_lod = lod;
  scene.adaptivity.secondary_rate_hz = rate_hz;
  return scene;
}

// Real threads on real clocks against the deterministic virtual-time schedule of the same
// configuration. They differ only where the secondary reads the primary's state: the threaded
// secondary is released 1.25 primary periods early and extrapolates from the state just before
// its own time, where the virtual schedule may use the state at that time exactly. That changes
// the force by about 0.01 % here; the bound, 0.1 % relative L2, is far below both the smallest
// adaptive error on this scene (0.4 %) and the 7 % JND. A run with a missed deadline reads older
// snapshots still, so it is retried (the machine is shared) and must then be clean.
#if defined(__SANITIZE_THREAD__) || defined(__SANITIZE_ADDRESS__)
constexpr bool kSanitized = true;  // slowed down many times: deadlines are not the point here
#else
constexpr bool kSanitized = false;
#endif

TEST(RealTimeSchedule, AgreesWithTheVirtualTimeRunWhenNoDeadlineIsMissed) {
  if (kSanitized) GTEST_SKIP() << "timing test; the sanitizer run covers the threads below";
  for (const Scene& scene : {Adaptive(3, 2, 600), Adaptive(2, 3, 700)}) {
    AsyncRegions regions(scene);
    const TrialResult virtual_time = regions.RunTrial();
    bool clean = false;
    for (int attempt = 0; attempt < 3 && !clean; ++attempt) {
      RealTimeSchedule dut(regions);
      const TrialResult threaded = dut.RunTrial();
      ASSERT_EQ(threaded.samples.size(), virtual_time.samples.size());
      if (dut.primary_stats().misses > 0 || dut.secondary_stats().misses > 0) continue;
      clean = true;
      EXPECT_EQ(dut.primary_stats().cycles, static_cast<long>(virtual_time.samples.size()));
      EXPECT_GT(dut.secondary_stats().cycles, 0);
      EXPECT_LT(CompareForces(threaded.samples, virtual_time.samples).l2_percent, 0.1);
    }
    EXPECT_TRUE(clean) << "every attempt missed a deadline";
  }
}

// Both threads at full speed with whatever timing the machine gives (under ThreadSanitizer this
// is the race check of the real exchange): the run completes with finite forces even when
// deadlines are missed, because a late region's state is held, not extrapolated.
TEST(RealTimeSchedule, CompletesWithFiniteForcesWhateverTheTiming) {
  AsyncRegions regions(Adaptive(2, 2, 600));
  RealTimeSchedule dut(regions);
  const TrialResult threaded = dut.RunTrial();
  EXPECT_EQ(threaded.outcome, TrialOutcome::kCompleted);
  EXPECT_EQ(threaded.samples.size(), 1001u);
  EXPECT_GT(threaded.peak_force_n, 1.0);
  EXPECT_LT(threaded.peak_force_n, 2.0);
}

}  // namespace
}  // namespace hapticsim
