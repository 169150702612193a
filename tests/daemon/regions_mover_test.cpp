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

TEST(RegionsMover, ATouchMovesAtOnceAndItsVerdictFollowsThenTheNodeIsKnown) {
  const Scene scene;
  RegionsMover mover(scene);
  const RegionConfiguration configuration{2, 2, 600};
  mover.Ask({configuration, kOffCentre, false}, Now());
  const std::optional<RegionsMover::Outcome> now = mover.Poll(Now());
  ASSERT_TRUE(now) << "a touch must not wait for the estimate";
  EXPECT_EQ(now->kind, Kind::kMoveUnverified);
  EXPECT_EQ(now->centred.configuration, configuration);
  EXPECT_EQ(now->centred.spectral_radius, -1);
  EXPECT_TRUE(mover.busy());
  EXPECT_TRUE(mover.verifying_behind());

  const RegionsMover::Outcome verdict = NextOutcome(mover);
  EXPECT_EQ(verdict.kind, Kind::kConfirmed);
  EXPECT_FALSE(verdict.moves());
  EXPECT_GT(verdict.centred.spectral_radius, 0);
  EXPECT_LT(verdict.centred.spectral_radius, 1);
  EXPECT_FALSE(mover.busy());

  // Touched again: straight to the verified configuration, no estimate.
  mover.Ask({configuration, kOffCentre, false}, Now());
  const std::optional<RegionsMover::Outcome> again = mover.Poll(Now());
  ASSERT_TRUE(again);
  EXPECT_EQ(again->kind, Kind::kMoveVerified);
  EXPECT_EQ(again->centred.spectral_radius, verdict.centred.spectral_radius);
  EXPECT_FALSE(mover.busy());
}

TEST(RegionsMover, ATouchWhereTheConfigurationIsUnstableIsDemotedToEqualRates) {
  Scene scene;
  scene.material.poisson_ratio = 0.49;  // k 1 r 2 700 Hz: 1.47 per common period, bare
  RegionsMover mover(scene);
  const RegionConfiguration configuration{2, 1, 700};
  mover.Ask({configuration, kOffCentre, false}, Now());
  const std::optional<RegionsMover::Outcome> now = mover.Poll(Now());
  ASSERT_TRUE(now);
  EXPECT_EQ(now->kind, Kind::kMoveUnverified);
  const RegionsMover::Outcome verdict = NextOutcome(mover);
  EXPECT_EQ(verdict.kind, Kind::kDemote);
  EXPECT_TRUE(verdict.moves());
  EXPECT_TRUE(verdict.centred.fell_back);
  EXPECT_EQ(verdict.centred.configuration, (RegionConfiguration{2, 1, PrimaryRateHz(scene)}));
  EXPECT_LT(verdict.centred.spectral_radius, 1);
  // Touched again: straight to the equal rates, verified.
  mover.Ask({configuration, kOffCentre, false}, Now());
  const std::optional<RegionsMover::Outcome> again = mover.Poll(Now());
  ASSERT_TRUE(again);
  EXPECT_EQ(again->kind, Kind::kMoveVerified);
  EXPECT_TRUE(again->centred.fell_back);
}

TEST(RegionsMover, ANodeTheToolCannotTouchIsRefusedAtOnceAndNotAskedAgain) {
  const Scene scene;
  RegionsMover mover(scene);
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
  RegionsMover mover(scene);
  const RegionConfiguration configuration{3, 2, 800};
  mover.Ask({configuration, kOffCentre, true}, Now());
  EXPECT_FALSE(mover.verifying_behind());
  const RegionsMover::Outcome verdict = NextOutcome(mover);
  EXPECT_EQ(verdict.kind, Kind::kMoveVerified);
  EXPECT_EQ(verdict.centred.configuration, configuration);
  EXPECT_LT(verdict.centred.spectral_radius, 1);
  EXPECT_GT(verdict.elapsed_ms, 0);
}

}  // namespace
}  // namespace hapticsim
