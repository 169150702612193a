// The stability stress test's own parts: deterministic draws, steps placed around a region's limit,
// and the detection bound. The 1,000-case run itself is the Stress.* CTest (label stress).
#include "core/regions/stability_stress.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "core/regions/async_regions.hpp"

namespace hapticsim {
namespace {

TEST(StabilityStress, ACaseDependsOnlyOnTheSeedAndItsIndex) {
  const StressRanges ranges;
  EXPECT_EQ(DescribeStressCase(DrawStressCase(5, 17, ranges)),
            DescribeStressCase(DrawStressCase(5, 17, ranges)));
  EXPECT_NE(DescribeStressCase(DrawStressCase(5, 17, ranges)),
            DescribeStressCase(DrawStressCase(5, 18, ranges)));
  EXPECT_NE(DescribeStressCase(DrawStressCase(5, 17, ranges)),
            DescribeStressCase(DrawStressCase(6, 17, ranges)));
}

TEST(StabilityStress, NearLimitCasesPutOneRegionsStepAroundItsOwnLimit) {
  const StressRanges ranges;
  int near_limit = 0, past = 0, below = 0;
  for (int i = 0; i < 40; ++i) {
    const StressCase c = DrawStressCase(3, i, ranges);
    ValidateScene(c.scene);
    if (c.substep_safety == AsyncRegions::kSubstepSafety) continue;
    ++near_limit;
    const AsyncRegions regions(c.scene, c.substep_safety);
    // Every region takes one step per period; one of them sits at its drawn 0.8–1.3 of its limit.
    bool placed = false;
    double largest = 0;
    for (int r = 0; r < regions.num_regions(); ++r) {
      EXPECT_EQ(regions.schedule(r).substeps, 1);
      const double ratio =
          1.0 / regions.schedule(r).rate_hz / regions.schedule(r).alone.critical_dt_s;
      placed = placed || (ratio > 0.8 - 1e-6 && ratio < 1.3 + 1e-6);
      largest = std::max(largest, ratio);
    }
    EXPECT_TRUE(placed) << DescribeStressCase(c);
    (largest >= 1 ? past : below) += 1;
  }
  EXPECT_GE(near_limit, 8);  // two in five of 40
  EXPECT_GE(past, 2);
  EXPECT_GE(below, 2);
}

TEST(StabilityStress, TheDetectionBoundShrinksAsTheGrowthRises) {
  const double common = 0.01, dt = 0.001;
  EXPECT_EQ(DetectionBoundPeriods(0.99, common, dt), -1);  // decaying: nothing to detect
  const long slow = DetectionBoundPeriods(1.01, common, dt);
  const long fast = DetectionBoundPeriods(2.0, common, dt);
  EXPECT_GT(slow, fast);
  // ln(1e4 / 1e-20) / (2 ln 2) ≈ 39.9 common periods + 100, ten primary periods each.
  EXPECT_EQ(fast, 1399);
  EXPECT_EQ(DetectionBoundPeriods(INFINITY, common, dt), 1000);
}

TEST(StabilityStress, ARegionPastItsLimitDivergesAndIsNamedAndOneBelowStaysBounded) {
  // Search the draw for one case of each kind (deterministic: the same cases every run).
  StressRanges ranges;
  ranges.stable_run_s = 1.0;
  bool saw_past = false, saw_below = false;
  for (int i = 0; i < 60 && !(saw_past && saw_below); ++i) {
    const StressCase c = DrawStressCase(9, i, ranges);
    if (c.substep_safety == AsyncRegions::kSubstepSafety) continue;
    const StressOutcome out = RunStressCase(c, ranges);
    if (out.past_limit && !out.marginal && !saw_past) {
      saw_past = true;
      EXPECT_TRUE(out.diverged()) << DescribeStressCase(c);
      EXPECT_LE(out.periods_run, out.bound_periods);
      ASSERT_GE(out.diverged_region, 0);
      EXPECT_GE(out.step_over_limit[static_cast<size_t>(out.diverged_region)], 1.0);
    }
    if (out.predicted_stable && !saw_below) {
      saw_below = true;
      EXPECT_FALSE(out.diverged()) << DescribeStressCase(c);
      EXPECT_EQ(out.periods_run, std::lround(1.0 / c.scene.solver.dt_s) + 1);
    }
  }
  EXPECT_TRUE(saw_past);
  EXPECT_TRUE(saw_below);
}

}  // namespace
}  // namespace hapticsim
