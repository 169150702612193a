// The supervisor's mover: a touch moves the regions at once and its verdict follows (confirmed,
// demoted to equal rates, or sent back where they were last verified); a configuration change
// and a hovering tool's move are verified first; a node the tool cannot touch is refused at once.
#include "daemon/regions_mover.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "core/error.hpp"
#include "core/regions/async_regions.hpp"
#include "core/scene/scene.hpp"

namespace hapticsim {
namespace {

using Kind = RegionsMover::Outcome::Kind;
const LatticeIndex kOffCentre{2, 3, 0};
const LatticeIndex kElsewhere{9, 4, 0};

std::int64_t Now() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

RegionsMover::Request Touch(const RegionConfiguration& configuration, const LatticeIndex& node) {
  return {configuration, node, /*applies_pending=*/false, /*touch_waits=*/true};
}

// The regions at start: the scene's own configuration on its own node, verified.
RegionsMover::Placement AtStart(const Scene& scene) {
  return {{{scene.adaptivity.primary_size, scene.adaptivity.secondary_lod,
            scene.adaptivity.secondary_rate_hz},
           true,
           false},
          ContactNode(scene)};
}

// What the supervisor does with an outcome: moves the regions, then tells the mover.
std::optional<RegionsMover::Outcome> PollAndApply(RegionsMover& mover) {
  std::optional<RegionsMover::Outcome> out = mover.Poll(Now());
  if (out) mover.Applied(*out);
  return out;
}

// Polls (and applies) until the mover has something to say (a verification takes well under a
// minute here).
RegionsMover::Outcome NextOutcome(RegionsMover& mover) {
  const std::int64_t give_up = Now() + 60'000'000'000;
  while (Now() < give_up) {
    if (std::optional<RegionsMover::Outcome> out = PollAndApply(mover)) return *out;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  ADD_FAILURE() << "no verdict within 60 s";
  return {};
}

// A verdict no scene here gives — regions whose partition is valid around a node but that cannot
// be built there — from a stand-in for VerifyCentredOn: `refused` is refused, any other node runs.
RegionsMover::Verifier RefusingAt(const LatticeIndex& refused) {
  return [refused](const Scene&, const RegionConfiguration& configuration,
                   const LatticeIndex& node) -> CentredConfiguration {
    if (node == refused) throw Error("cannot run there");
    return {configuration, true, false};
  };
}

// The very next Poll refuses the move, with `reason` in its message.
void ExpectRefusedAtOnce(RegionsMover& mover, const std::string& reason) {
  try {
    (void)mover.Poll(Now());
    ADD_FAILURE() << "moved, where it should be refused: " << reason;
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(reason), std::string::npos) << e.what();
  }
}

TEST(RegionsMover, ATouchMovesAtOnceAndItsVerdictFollowsThenTheNodeIsKnown) {
  const Scene scene;
  RegionsMover mover(scene, AtStart(scene));
  const RegionConfiguration configuration{2, 2, 600};
  mover.Ask(Touch(configuration, kOffCentre), Now());
  const std::optional<RegionsMover::Outcome> now = PollAndApply(mover);
  ASSERT_TRUE(now) << "a touch must not wait for the estimate";
  EXPECT_EQ(now->kind, Kind::kMoveUnverified);
  EXPECT_EQ(now->to.centred.configuration, configuration);
  EXPECT_EQ(now->to.node, kOffCentre);
  EXPECT_EQ(mover.placement().node, kOffCentre);
  EXPECT_FALSE(mover.placement().centred.verified) << "checked behind the move";
  EXPECT_TRUE(mover.busy()) << "its verdict is still to come";

  const RegionsMover::Outcome verdict = NextOutcome(mover);
  EXPECT_EQ(verdict.kind, Kind::kConfirmed);
  EXPECT_FALSE(verdict.moves());
  EXPECT_TRUE(verdict.to.centred.verified);
  EXPECT_TRUE(mover.placement().centred.verified);
  EXPECT_NE(verdict.Describe().find("checked"), std::string::npos) << verdict.Describe();
  EXPECT_FALSE(mover.busy());

  // Touched again: straight to the verified configuration, no estimate.
  mover.Ask(Touch(configuration, kOffCentre), Now());
  const std::optional<RegionsMover::Outcome> again = PollAndApply(mover);
  ASSERT_TRUE(again);
  EXPECT_EQ(again->kind, Kind::kMoveVerified);
  EXPECT_TRUE(again->to.centred.verified);
  EXPECT_FALSE(mover.busy());
  // A verified move carries the object's motion only where the regions already are centred.
  EXPECT_TRUE(again->CarriesMotionFrom(kOffCentre));
  EXPECT_FALSE(again->CarriesMotionFrom(AtStart(scene).node));
  EXPECT_FALSE(now->CarriesMotionFrom(kOffCentre)) << "a move verified behind it starts from rest";
  // And the node the regions started on is known from the start.
  mover.Ask(Touch(AtStart(scene).centred.configuration, AtStart(scene).node), Now());
  const std::optional<RegionsMover::Outcome> home = PollAndApply(mover);
  ASSERT_TRUE(home);
  EXPECT_EQ(home->kind, Kind::kMoveVerified);
}

// The loop's runaway watch fired (AsyncRegions::Runaway): at the next Poll the regions go to
// equal rates where they are, from rest, whatever the mover was doing, and that configuration is
// not asked for around that node again.
TEST(RegionsMover, ARunawayDemotesTheRegionsToEqualRatesThereAndRefusesTheConfiguration) {
  const Scene scene;
  RegionsMover mover(scene, AtStart(scene), RefusingAt(kElsewhere));
  const RegionConfiguration configuration{2, 2, 600};
  mover.Ask(Touch(configuration, kOffCentre), Now());
  ASSERT_TRUE(PollAndApply(mover));  // moved unverified; its verdict is behind it
  mover.OnRunaway(Now());
  const std::optional<RegionsMover::Outcome> off = PollAndApply(mover);
  ASSERT_TRUE(off);
  EXPECT_EQ(off->kind, Kind::kDemote);
  EXPECT_TRUE(off->runaway);
  EXPECT_TRUE(off->moves());
  EXPECT_EQ(off->request.configuration, configuration);
  EXPECT_EQ(off->to.node, kOffCentre);
  EXPECT_EQ(off->to.centred.configuration.primary_size, 2);
  EXPECT_EQ(off->to.centred.configuration.secondary_lod, 2);
  EXPECT_EQ(off->to.centred.configuration.secondary_rate_hz, PrimaryRateHz(scene));
  EXPECT_EQ(off->to.centred.configuration.outer_rate_hz, 0) << "one shell: no outer rate";
  EXPECT_FALSE(off->CarriesMotionFrom(kOffCentre)) << "a state that ran away is not carried";
  EXPECT_NE(off->Describe().find("runaway watch"), std::string::npos) << off->Describe();
  EXPECT_EQ(mover.placement().centred.configuration, off->to.centred.configuration);
  EXPECT_TRUE(mover.placement().centred.verified);
  EXPECT_TRUE(mover.may_ask(Touch(configuration, AtStart(scene).node)));
  // The verdict the touch started is given up: nothing more comes from the mover.
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  EXPECT_FALSE(PollAndApply(mover));
  EXPECT_FALSE(mover.busy());
  // Away and back: a touch there asking for the configuration that ran away gets equal rates
  // straight away (not zero force while nothing is asked).
  mover.Ask(Touch(configuration, AtStart(scene).node), Now());
  ASSERT_TRUE(PollAndApply(mover));
  ASSERT_TRUE(mover.may_ask(Touch(configuration, kOffCentre)));
  mover.Ask(Touch(configuration, kOffCentre), Now());
  const std::optional<RegionsMover::Outcome> back = PollAndApply(mover);
  ASSERT_TRUE(back);
  EXPECT_EQ(back->kind, Kind::kMoveVerified);
  EXPECT_TRUE(back->to.centred.fell_back);
  EXPECT_EQ(back->to.centred.configuration, off->to.centred.configuration);
  EXPECT_NE(back->Describe().find("ran away around it before"), std::string::npos)
      << back->Describe();
  EXPECT_FALSE(mover.busy());
  // Already at equal rates: the same regions again, from rest.
  mover.OnRunaway(Now());
  const std::optional<RegionsMover::Outcome> again = PollAndApply(mover);
  ASSERT_TRUE(again);
  EXPECT_EQ(again->to.centred.configuration, again->request.configuration);
  EXPECT_NE(again->Describe().find("already at equal rates"), std::string::npos);
}

// Equal rates are every shell's: with two shells and the first alone at the primary rate, the
// outer shell's own rate kept a multirate exchange, and in the order hapticsimd's threads step
// the regions four stress cases ran away again there (AtEqualRates).
TEST(RegionsMover, EqualRatesPutEveryShellAtThePrimaryRate) {
  Scene scene;
  scene.adaptivity.secondary_regions = 2;
  scene.adaptivity.outer_rate_hz = 500;
  const RegionConfiguration equal = AtEqualRates(scene, RegionConfiguration{2, 2, 600});
  const AsyncRegions regions(SceneWith(scene, equal));
  ASSERT_EQ(regions.num_regions(), 3);
  for (int a = 0; a < regions.num_regions(); ++a) {
    EXPECT_EQ(regions.schedule(a).rate_hz, PrimaryRateHz(scene)) << "region " << a;
  }
  EXPECT_EQ(DescribeConfiguration(equal),
            "primary_size 2, secondary_lod 2, secondary_rate 1000 Hz, outer_rate 1000 Hz");
  // Any other configuration keeps the scene's outer rate; one already at equal rates stays
  // itself, as with one shell.
  EXPECT_EQ(SceneWith(scene, RegionConfiguration{2, 2, 600}).adaptivity.outer_rate_hz, 500);
  EXPECT_EQ(AtEqualRates(scene, equal), equal);
  scene.adaptivity.outer_rate_hz = PrimaryRateHz(scene);
  EXPECT_EQ(AtEqualRates(scene, RegionConfiguration{2, 2, 1000}),
            (RegionConfiguration{2, 2, 1000}));
}

// Stable by construction (docs/regions.md): a configuration whose bare exchange grows — the
// spectral estimate this mover used to run refused it — runs as asked, its regions each within
// their own limit and the interface controllers holding the coupling.
TEST(RegionsMover, ATouchWhereTheBareExchangeGrowsRunsThereAsAsked) {
  Scene scene;
  scene.material.poisson_ratio = 0.49;  // k 1 r 2 700 Hz: 1.47 per common period, bare
  RegionsMover mover(scene, AtStart(scene));
  const RegionConfiguration configuration{2, 1, 700};
  mover.Ask(Touch(configuration, kOffCentre), Now());
  const std::optional<RegionsMover::Outcome> now = PollAndApply(mover);
  ASSERT_TRUE(now);
  EXPECT_EQ(now->kind, Kind::kMoveUnverified);
  const RegionsMover::Outcome verdict = NextOutcome(mover);
  EXPECT_EQ(verdict.kind, Kind::kConfirmed);
  EXPECT_FALSE(verdict.moves());
  EXPECT_FALSE(verdict.to.centred.fell_back);
  EXPECT_EQ(verdict.to.centred.configuration, configuration);
  EXPECT_EQ(mover.placement().centred.configuration, configuration);
  // Touched again: straight there, as asked.
  mover.Ask(Touch(configuration, kOffCentre), Now());
  const std::optional<RegionsMover::Outcome> again = PollAndApply(mover);
  ASSERT_TRUE(again);
  EXPECT_EQ(again->kind, Kind::kMoveVerified);
  EXPECT_EQ(again->to.centred.configuration, configuration);
}

TEST(RegionsMover, ANodeTheToolCannotTouchIsRefusedAtOnceAndNotAskedAgain) {
  const Scene scene;
  RegionsMover mover(scene, AtStart(scene));
  const RegionsMover::Request inside = Touch({2, 2, 600}, {6, 6, 6});
  mover.Ask(inside, Now());
  ExpectRefusedAtOnce(mover, "\"6,6,6\" is inside the object");
  EXPECT_FALSE(mover.busy());
  EXPECT_FALSE(mover.may_ask(inside));
}

TEST(RegionsMover, AConfigurationChangeAndAHoverAreVerifiedBeforeTheyMove) {
  const Scene scene;
  RegionsMover mover(scene, AtStart(scene));
  const RegionConfiguration configuration{3, 2, 800};
  mover.Ask({configuration, kOffCentre, /*applies_pending=*/true, /*touch_waits=*/false}, Now());
  EXPECT_FALSE(mover.Poll(Now())) << "a configuration change moves only once verified";
  const RegionsMover::Outcome verdict = NextOutcome(mover);
  EXPECT_EQ(verdict.kind, Kind::kMoveVerified);
  EXPECT_EQ(verdict.to.centred.configuration, configuration);
  EXPECT_TRUE(verdict.to.centred.verified);
  EXPECT_GT(verdict.elapsed_ms, 0);
  EXPECT_EQ(mover.placement().node, kOffCentre);

  // A tool hovering over another node: nobody waits, so verified first too.
  mover.Ask({configuration, kElsewhere, false, false}, Now());
  EXPECT_FALSE(mover.Poll(Now())) << "a hover moves only once verified";
  const RegionsMover::Outcome hover = NextOutcome(mover);
  EXPECT_EQ(hover.kind, Kind::kMoveVerified);
  EXPECT_EQ(mover.placement().node, kElsewhere);
}

TEST(RegionsMover, RegionsThatCannotBeBuiltAroundTheNodeAreRefusedBeforeTheyMove) {
  Scene scene;
  scene.adaptivity.secondary_regions = 4;  // primary_size 2 leaves the fourth shell empty
  scene.adaptivity.shell_cells = 2;
  RegionsMover mover(scene, AtStart(scene));
  const RegionsMover::Placement before = mover.placement();
  mover.Ask(Touch({2, 2, 600}, kOffCentre), Now());
  ExpectRefusedAtOnce(mover, "leaves secondary region 4");
  EXPECT_EQ(mover.placement().node, before.node);
  EXPECT_FALSE(mover.busy());
}

TEST(RegionsMover, ANodeTheCheckRefusesSendsTheRegionsBackWhereTheyWereLastChecked) {
  const Scene scene;
  RegionsMover mover(scene, AtStart(scene), RefusingAt(kElsewhere));
  const RegionConfiguration configuration{2, 2, 600};
  // A touch at one node, confirmed there: the last checked place is now that node.
  mover.Ask(Touch(configuration, kOffCentre), Now());
  ASSERT_EQ(PollAndApply(mover)->kind, Kind::kMoveUnverified);
  ASSERT_EQ(NextOutcome(mover).kind, Kind::kConfirmed);
  // Then one at a node it refuses: moved at once, then sent back to the confirmed node.
  const RegionsMover::Request refused = Touch(configuration, kElsewhere);
  mover.Ask(refused, Now());
  ASSERT_EQ(PollAndApply(mover)->kind, Kind::kMoveUnverified);
  EXPECT_EQ(mover.placement().node, kElsewhere);
  const RegionsMover::Outcome verdict = NextOutcome(mover);
  EXPECT_EQ(verdict.kind, Kind::kMoveBack);
  EXPECT_EQ(verdict.to.node, kOffCentre);
  EXPECT_EQ(verdict.to.centred.configuration, configuration);
  EXPECT_EQ(mover.placement().node, kOffCentre);
  EXPECT_NE(verdict.Describe().find("cannot run there; the regions go back to contact node "
                                    "(2, 3, 0)"),
            std::string::npos)
      << verdict.Describe();
  EXPECT_FALSE(mover.may_ask(refused));
}

TEST(RegionsMover, AMoveBackThatCouldNotBeAppliedIsAskedForAgain) {
  const Scene scene;
  RegionsMover mover(scene, AtStart(scene), RefusingAt(kOffCentre));
  mover.Ask(Touch({2, 2, 600}, kOffCentre), Now());
  ASSERT_EQ(PollAndApply(mover)->kind, Kind::kMoveUnverified);
  std::optional<RegionsMover::Outcome> back;
  for (int i = 0; i < 30000 && !back; ++i) {  // not applied: the loop did not answer
    back = mover.Poll(Now());
    if (!back) std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  ASSERT_TRUE(back);
  ASSERT_EQ(back->kind, Kind::kMoveBack);
  mover.NotApplied(*back);
  EXPECT_EQ(mover.placement().node, kOffCentre) << "the regions still run there";
  EXPECT_FALSE(mover.may_interrupt()) << "a move back is not given up for a touch";
  const std::optional<RegionsMover::Outcome> again = mover.Poll(Now());
  ASSERT_TRUE(again) << "asked for again at the next poll";
  EXPECT_EQ(again->kind, Kind::kMoveBack);
  mover.Applied(*again);
  EXPECT_EQ(mover.placement().node, AtStart(scene).node);
  EXPECT_FALSE(mover.busy());
}

TEST(RegionsMover, ATouchElsewhereGivesUpTheVerificationBehindTheLastOne) {
  const Scene scene;
  RegionsMover mover(scene, AtStart(scene), RefusingAt({0, 0, 0}));
  mover.Ask(Touch({2, 2, 600}, kOffCentre), Now());
  ASSERT_EQ(PollAndApply(mover)->kind, Kind::kMoveUnverified);
  ASSERT_TRUE(mover.may_interrupt());
  mover.Ask(Touch({2, 2, 600}, kElsewhere), Now());
  ASSERT_EQ(PollAndApply(mover)->kind, Kind::kMoveUnverified);
  const RegionsMover::Outcome verdict = NextOutcome(mover);
  EXPECT_EQ(verdict.kind, Kind::kConfirmed);
  EXPECT_EQ(verdict.request.node, kElsewhere) << "the verdict is the newest touch's";
  EXPECT_EQ(mover.placement().node, kElsewhere);
  EXPECT_FALSE(mover.busy());
}

}  // namespace
}  // namespace hapticsim
