// The virtual-time runs' two orders (SteppingOrder): where every region takes one substep a
// period at one rate they are the same schedule, so the same forces; elsewhere the threads' order
// is what hapticsimd's threads run (tests/threads/realtime_schedule_test.cpp checks that on real
// threads).
#include "core/regions/stepping_order.hpp"

#include <gtest/gtest.h>

#include <string>
#include <utility>
#include <vector>

#include "core/regions/async_regions.hpp"
#include "core/trial/force_error.hpp"
#include "tests/support/adaptive_scene.hpp"

namespace hapticsim {
namespace {

TrialResult PressIn(const Scene& scene, SteppingOrder order) {
  AsyncRegions regions(scene);
  regions.SetSteppingOrder(order);
  return regions.RunTrial();
}

// At one rate in one substep a secondary released half a period ahead finds the primary at its
// own period's start and publishes Γ before the primary needs it: what the substeps' order does.
TEST(SteppingOrder, AtOneRateInOneSubstepBothOrdersGiveTheSameForce) {
  Scene shells = testing::AdaptiveScene(2, 2, 1000);
  shells.adaptivity.secondary_regions = 2;
  shells.adaptivity.outer_rate_hz = 1000;
  const std::vector<std::pair<std::string, Scene>> scenes{
      {"one shell", testing::AdaptiveScene(3, 2, 1000)}, {"two shells", shells}};
  for (auto [label, scene] : scenes) {
    scene.input.periods = 0.5;
    AsyncRegions regions(scene);
    for (RegionIndex r = 0; r < regions.num_regions(); ++r) {
      ASSERT_EQ(regions.schedule(r).substeps, 1) << label << ", region " << r;
    }
    const TrialResult substeps = PressIn(scene, SteppingOrder::kSubsteps);
    const TrialResult threads = PressIn(scene, SteppingOrder::kThreads);
    ASSERT_EQ(threads.samples.size(), substeps.samples.size()) << label;
    EXPECT_GT(substeps.peak_force_n, 0.5) << label;
    EXPECT_LT(CompareForces(threads.samples, substeps.samples).l2_percent, 1e-9) << label;
  }
}

// At another rate the threads' order reads the primary's band older: a different force, but the
// same press (both near the reference's peak on the default material, where the map's error is
// a few tenths of a percent in either order: 0.403 % and 0.407 % at k 2 r 3 600 Hz).
TEST(SteppingOrder, AtAnotherRateOnTheDefaultMaterialBothOrdersAreThePress) {
  Scene scene = testing::AdaptiveScene(3, 2, 600);
  scene.input.periods = 0.5;
  const TrialResult substeps = PressIn(scene, SteppingOrder::kSubsteps);
  const TrialResult threads = PressIn(scene, SteppingOrder::kThreads);
  ASSERT_EQ(threads.samples.size(), substeps.samples.size());
  const double l2 = CompareForces(threads.samples, substeps.samples).l2_percent;
  EXPECT_GT(l2, 0) << "the orders must differ at another rate";
  EXPECT_LT(l2, 0.5);
}

TEST(SteppingOrder, NamesRoundTrip) {
  for (SteppingOrder order : {SteppingOrder::kSubsteps, SteppingOrder::kThreads}) {
    EXPECT_EQ(SteppingOrderNamed(SteppingOrderName(order)), order);
  }
  EXPECT_FALSE(SteppingOrderNamed("sideways"));
}

}  // namespace
}  // namespace hapticsim
