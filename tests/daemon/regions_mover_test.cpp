// The supervisor's mover: a touch moves the regions at once and its verdict follows; a
// configuration change is verified first; a node the tool cannot touch is refused at once.
#include "daemon/regions_mover.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "core/error.hpp"
#include "core/scene.hpp"

namespace hapticsim {
namespace {

std::int64_t Now() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

// Polls until the mover has something to say (a verification takes well under a minute here).
RegionsMover::Outcome NextOutcome(RegionsMover& mover) {
  const std::int64_t give_up = Now() + 60'000'000'000;
  while (Now() < give_up) {
    if (std::optional<RegionsMover::Outcome> out = mover.Poll(Now())) return *out;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  ADD_FAILURE() << "no verdict within 60 s";
  return {};
}

using Kind = RegionsMover::Outcome::Kind;
const LatticeIndex kOffCentre{2, 3, 0};

// The regions at start: the scene's own configuration on its own node, verified.
RegionsMover::Placement AtStart(const Scene& scene) {
  return {{{scene.adaptivity.primary_size, scene.adaptivity.secondary_lod,
            scene.adaptivity.secondary_rate_hz},
           0.99,
           false},
          ContactNode(scene)};
}

TEST(RegionsMover, ATouchMovesAtOnceAndItsVerdictFollowsThenTheNodeIsKnown) {
  const Scene scene;
  RegionsMover mover(scene, AtStart(scene));
  const RegionConfiguration configuration{2, 2, 600};
  mover.Ask({configuration, kOffCentre, false}, Now());
  const std::optional<RegionsMover::Outcome> now = mover.Poll(Now());
  ASSERT_TRUE(now) << "a touch must not wait for the estimate";
  EXPECT_EQ(now->kind, Kind::kMoveUnverified);
  EXPECT_EQ(now->to.centred.configuration, configuration);
  EXPECT_EQ(now->to.node, kOffCentre);
  EXPECT_EQ(mover.placement().centred.spectral_radius, -1) << "unverified";
  EXPECT_TRUE(mover.busy()) << "its verdict is still to come";

  const RegionsMover::Outcome verdict = NextOutcome(mover);
  EXPECT_EQ(verdict.kind, Kind::kConfirmed);
  EXPECT_FALSE(verdict.moves());
  EXPECT_GT(verdict.to.centred.spectral_radius, 0);
  EXPECT_LT(verdict.to.centred.spectral_radius, 1);
  EXPECT_EQ(mover.placement().centred.spectral_radius, verdict.to.centred.spectral_radius);
  EXPECT_NE(verdict.Describe().find("verified"), std::string::npos) << verdict.Describe();
  EXPECT_FALSE(mover.busy());

  // Touched again: straight to the verified configuration, no estimate.
  mover.Ask({configuration, kOffCentre, false}, Now());
  const std::optional<RegionsMover::Outcome> again = mover.Poll(Now());
  ASSERT_TRUE(again);
  EXPECT_EQ(again->kind, Kind::kMoveVerified);
  EXPECT_EQ(again->to.centred.spectral_radius, verdict.to.centred.spectral_radius);
  EXPECT_FALSE(mover.busy());
}

TEST(RegionsMover, ATouchWhereTheConfigurationIsUnstableIsDemotedToEqualRates) {
  Scene scene;
  scene.material.poisson_ratio = 0.49;  // k 1 r 2 700 Hz: 1.47 per common period, bare
  RegionsMover mover(scene, AtStart(scene));
  const RegionConfiguration configuration{2, 1, 700};
  mover.Ask({configuration, kOffCentre, false}, Now());
  const std::optional<RegionsMover::Outcome> now = mover.Poll(Now());
  ASSERT_TRUE(now);
  EXPECT_EQ(now->kind, Kind::kMoveUnverified);
  const RegionsMover::Outcome verdict = NextOutcome(mover);
  EXPECT_EQ(verdict.kind, Kind::kDemote);
  EXPECT_TRUE(verdict.moves());
  EXPECT_TRUE(verdict.to.centred.fell_back);
  EXPECT_EQ(verdict.to.centred.configuration, (RegionConfiguration{2, 1, PrimaryRateHz(scene)}));
  EXPECT_EQ(verdict.to.node, kOffCentre);
  EXPECT_LT(verdict.to.centred.spectral_radius, 1);
  EXPECT_EQ(mover.placement().centred.configuration, verdict.to.centred.configuration);
  EXPECT_NE(verdict.Describe().find("UNSTABLE"), std::string::npos) << verdict.Describe();
  // Touched again: straight to the equal rates, verified.
  mover.Ask({configuration, kOffCentre, false}, Now());
  const std::optional<RegionsMover::Outcome> again = mover.Poll(Now());
  ASSERT_TRUE(again);
  EXPECT_EQ(again->kind, Kind::kMoveVerified);
  EXPECT_TRUE(again->to.centred.fell_back);
}

TEST(RegionsMover, ANodeTheToolCannotTouchIsRefusedAtOnceAndNotAskedAgain) {
  const Scene scene;
  RegionsMover mover(scene, AtStart(scene));
  const RegionsMover::Request inside{{2, 2, 600}, {6, 6, 6}, false};
  mover.Ask(inside, Now());
  try {
    (void)mover.Poll(Now());
    ADD_FAILURE() << "an interior node was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("\"6,6,6\" is inside the object"), std::string::npos)
        << e.what();
  }
  EXPECT_FALSE(mover.busy());
  EXPECT_FALSE(mover.may_ask(inside));
}

TEST(RegionsMover, AConfigurationChangeIsVerifiedBeforeItMoves) {
  const Scene scene;
  RegionsMover mover(scene, AtStart(scene));
  const RegionConfiguration configuration{3, 2, 800};
  mover.Ask({configuration, kOffCentre, true}, Now());
  EXPECT_FALSE(mover.Poll(Now())) << "a configuration change moves only once verified";
  const RegionsMover::Outcome verdict = NextOutcome(mover);
  EXPECT_EQ(verdict.kind, Kind::kMoveVerified);
  EXPECT_EQ(verdict.to.centred.configuration, configuration);
  EXPECT_LT(verdict.to.centred.spectral_radius, 1);
  EXPECT_GT(verdict.elapsed_ms, 0);
  EXPECT_EQ(mover.placement().node, kOffCentre);
}

TEST(RegionsMover, RegionsThatCannotBeBuiltAroundTheNodeAreRefusedBeforeTheyMove) {
  Scene scene;
  scene.adaptivity.secondary_regions = 4;  // primary_size 2 leaves the fourth shell empty
  scene.adaptivity.shell_cells = 2;
  RegionsMover mover(scene, AtStart(scene));
  const RegionsMover::Placement before = mover.placement();
  mover.Ask({{2, 2, 600}, kOffCentre, false}, Now());
  try {
    (void)mover.Poll(Now());
    ADD_FAILURE() << "regions with an empty shell were moved";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("leaves secondary region 4"), std::string::npos)
        << e.what();
  }
  EXPECT_EQ(mover.placement().node, before.node);
  EXPECT_FALSE(mover.busy());
}

// No scene here is unstable around a node even at equal rates (every equal-rate configuration of
// the paper's grid is stable, docs/regions.md), so the verdict comes from a stand-in.
TEST(RegionsMover, ANodeUnstableEvenAtEqualRatesSendsTheRegionsBackWhereTheyWereVerified) {
  const Scene scene;
  RegionsMover mover(
      scene, AtStart(scene),
      [](const Scene&, const RegionConfiguration&, const LatticeIndex&) -> CentredConfiguration {
        throw Error("not stable, not even at equal rates");
      });
  const RegionsMover::Placement start = mover.placement();
  const RegionsMover::Request touch{{2, 2, 600}, kOffCentre, false};
  mover.Ask(touch, Now());
  const std::optional<RegionsMover::Outcome> now = mover.Poll(Now());
  ASSERT_TRUE(now);
  EXPECT_EQ(now->kind, Kind::kMoveUnverified);
  const RegionsMover::Outcome verdict = NextOutcome(mover);
  EXPECT_EQ(verdict.kind, Kind::kMoveBack);
  EXPECT_EQ(verdict.to.node, start.node);
  EXPECT_EQ(verdict.to.centred.configuration, start.centred.configuration);
  EXPECT_EQ(mover.placement().node, start.node);
  EXPECT_NE(verdict.Describe().find("not even at equal rates; the regions go back to"),
            std::string::npos)
      << verdict.Describe();
  EXPECT_FALSE(mover.may_ask(touch));
}

}  // namespace
}  // namespace hapticsim
