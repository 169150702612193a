// The primary thread's contact logic on its own: which node a touch picks, how far it is driven,
// and how a late engagement ramps in.
#include "daemon/contact_tracker.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "daemon/input_resampler.hpp"

namespace hapticsim {
namespace {

constexpr double kEdge = 0.25, kH = kEdge / 12;  // the default 13³ cube
constexpr std::int64_t kMs = 1'000'000;

MeshSettings Mesh() { return MeshSettings{}; }
// The default cube as the daemon's tracker sees it: a box of 13³ nodes, its back corners held.
const ContactObject& CubeBox() {
  static const ContactObject box = ContactObject::Of(Scene{});
  return box;
}

TEST(ContactTracker, ATouchOnTheCentredNodeEngagesAtOnceAndFollowsTheTip) {
  ContactTracker tracker(CubeBox(), 0.1);
  const LatticeIndex middle{6, 6, 0};
  EXPECT_FALSE(tracker.Update({0.125, 0.125, -0.002}, 0, middle).engaged);
  EXPECT_EQ(tracker.wanted_node(), middle);
  const auto touch = tracker.Update({0.126, 0.124, 0.0005}, kMs, middle);
  EXPECT_TRUE(touch.engaged);
  EXPECT_FALSE(touch.waiting);
  // Entry point: the tip projected on the front face; the node follows the tip from there.
  EXPECT_DOUBLE_EQ(touch.displacement_m[2], 0.0005);
  EXPECT_DOUBLE_EQ(touch.displacement_m[0], 0.0);
  // In by 3.5 mm and across by 1 mm over 0.1 s (35 mm/s, a brisk press): every period the node is
  // where the tip is.
  ContactTracker::Contact deeper;
  for (int n = 1; n <= 100; ++n) {
    const std::array<double, 3> tip{0.126 + 0.001 * n / 100, 0.124, 0.0005 + 0.0035 * n / 100};
    deeper = tracker.Update(tip, (1 + n) * kMs, middle);
    ASSERT_NEAR(deeper.displacement_m[2], tip[2], 1e-15) << n;
  }
  EXPECT_NEAR(deeper.displacement_m[0], 0.001, 1e-15);
  EXPECT_NEAR(deeper.displacement_m[2], 0.004, 1e-15);
  // Sliding along the surface does not change the node (the paper's contact does not slide).
  tracker.Update({0.2, 0.124, 0.004}, 102 * kMs, middle);
  EXPECT_EQ(tracker.wanted_node(), middle);
  EXPECT_FALSE(tracker.Update({0.2, 0.124, -0.001}, 103 * kMs, middle).engaged);  // lift-off
}

TEST(ContactTracker, ATouchThroughAnyFacePicksTheNearestNodeOnThatFace) {
  struct Case {
    std::array<double, 3> outside, inside;
    LatticeIndex node;
    std::array<double, 3> displacement;
  };
  const double d = 0.0004;  // within kDeepTouchDown_m: engaged at once
  const Case cases[] = {
      {{0.1, 0.2, -d}, {0.1, 0.2, d}, {5, 10, 0}, {0, 0, d}},                   // front, z = 0
      {{0.1, 0.2, kEdge + d}, {0.1, 0.2, kEdge - d}, {5, 10, 12}, {0, 0, -d}},  // back
      {{-d, 0.05, 0.12}, {d, 0.05, 0.12}, {0, 2, 6}, {d, 0, 0}},                // left, x = 0
      {{kEdge + d, 0.05, 0.12}, {kEdge - d, 0.05, 0.12}, {12, 2, 6}, {-d, 0, 0}},
      {{0.07, -d, 0.2}, {0.07, d, 0.2}, {3, 0, 10}, {0, d, 0}},  // bottom, y = 0
      {{0.07, kEdge + d, 0.2}, {0.07, kEdge - d, 0.2}, {3, 12, 10}, {0, -d, 0}},
  };
  for (const Case& c : cases) {
    ContactTracker tracker(CubeBox(), 0.1);
    tracker.Update(c.outside, 0, c.node);
    EXPECT_EQ(tracker.wanted_node(), c.node) << "hovering";
    const auto contact = tracker.Update(c.inside, kMs, c.node);
    EXPECT_EQ(tracker.wanted_node(), c.node);
    ASSERT_TRUE(contact.engaged);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(contact.displacement_m[k], c.displacement[k], 1e-15);
  }
}

TEST(ContactTracker, AFixedBackCornerIsNeverTheContactNode) {
  const ContactTracker tracker(CubeBox(), 0.1);
  // Near the corner (0, 0, 12), a little farther from it along y than along x.
  const std::optional<LatticeIndex> nearest =
      tracker.NearestContactNode({0.2 * kH, 0.4 * kH, kEdge});
  ASSERT_TRUE(nearest);
  const LatticeIndex node = *nearest;
  EXPECT_FALSE(IsSupportNode(Mesh(), node));
  EXPECT_TRUE(IsSurfaceNode(Mesh(), node));
  EXPECT_EQ(node, (LatticeIndex{0, 1, 12}));
  EXPECT_EQ(tracker.NearestContactNode({kEdge, kEdge - 0.4 * kH, kEdge - 0.2 * kH}),
            std::optional<LatticeIndex>(LatticeIndex{12, 11, 12}));
}

TEST(ContactTracker, ATouchElsewhereWaitsThenRampsItsDepthInFromZero) {
  const double ramp_s = 0.1;
  ContactTracker tracker(CubeBox(), ramp_s);
  const LatticeIndex middle{6, 6, 0}, side{2, 3, 0};
  tracker.Update({2 * kH, 3 * kH, -0.001}, 0, middle);
  EXPECT_EQ(tracker.wanted_node(), side);
  // Pressing on at 10 mm/s while the regions are still around the middle: zero, waiting.
  std::int64_t t = 0;
  double z = 0;
  for (int n = 1; n <= 200; ++n) {
    t = n * kMs, z = 1e-5 * n;
    const auto c = tracker.Update({2 * kH, 3 * kH, z}, t, middle);
    ASSERT_TRUE(c.waiting);
    ASSERT_FALSE(c.engaged);
    ASSERT_EQ(c.displacement_m[2], 0.0);
  }
  EXPECT_EQ(tracker.wanted_node(), side);
  // The regions move (none while they are replaced), then the contact engages at zero depth and
  // the 2 mm it went in the meantime ramps in over ramp_s, on top of the tip's own motion.
  EXPECT_TRUE(tracker.Update({2 * kH, 3 * kH, z}, t += kMs, std::nullopt).waiting);
  double previous = 0, largest_step = 0;
  const double engaged_at_depth = z + 1e-5;
  for (int n = 0; n <= 150; ++n, t += kMs) {
    z += 1e-5;
    const auto c = tracker.Update({2 * kH, 3 * kH, z}, t, side);
    ASSERT_TRUE(c.engaged);
    if (n == 0) {
      EXPECT_NEAR(c.displacement_m[2], 0.0, 1e-15);
    }
    largest_step = std::max(largest_step, c.displacement_m[2] - previous);
    previous = c.displacement_m[2];
  }
  EXPECT_NEAR(previous, z, 1e-15);  // fully in after the ramp
  // d(w·D)/dn = w'·D + w·D': a smoothstep's steepest slope is 1.5 per ramp (100 periods) and D
  // is at most the depth at the ramp's end; the tip adds its 0.01 mm per period.
  const double depth_at_ramp_end = engaged_at_depth + 100 * 1e-5;
  EXPECT_LT(largest_step, 1.5 * depth_at_ramp_end / 100 + 1e-5);
  EXPECT_GT(largest_step, engaged_at_depth / 100);
}

TEST(ContactTracker, AfterARestartFromRestATipInsideMustLiftOffFirst) {
  ContactTracker tracker(CubeBox(), 0.1);
  const LatticeIndex middle{6, 6, 0};
  tracker.Update({0.125, 0.125, -0.001}, 0, middle);
  EXPECT_TRUE(tracker.Update({0.125, 0.125, 0.003}, kMs, middle).engaged);
  tracker.RestartFromRest();
  EXPECT_FALSE(tracker.Update({0.125, 0.125, 0.004}, 2 * kMs, middle).engaged);
  EXPECT_FALSE(tracker.Hold(3 * kMs, middle).engaged);
  tracker.Update({0.125, 0.125, -0.001}, 4 * kMs, middle);
  EXPECT_TRUE(tracker.Update({0.125, 0.125, 0.001}, 5 * kMs, middle).engaged);
  // A fresh tracker (a started loop) behaves the same: a tip already inside waits for lift-off.
  ContactTracker fresh(CubeBox(), 0.1);
  EXPECT_FALSE(fresh.Update({0.125, 0.125, 0.004}, 0, middle).engaged);
}

TEST(ContactTracker, ARestartKeepingContactEngagesAgainFromZero) {
  ContactTracker tracker(CubeBox(), 0.1);
  const LatticeIndex middle{6, 6, 0};
  tracker.Update({0.125, 0.125, -0.001}, 0, middle);
  tracker.Update({0.125, 0.125, 0.003}, kMs, middle);
  tracker.RestartKeepingContact();
  const auto again = tracker.Update({0.125, 0.125, 0.003}, 2 * kMs, middle);
  EXPECT_TRUE(again.engaged);
  EXPECT_NEAR(again.displacement_m[2], 0.0, 1e-15);
  const std::array<double, 3> tip{0.125, 0.125, 0.003};
  EXPECT_NEAR(tracker.Update(tip, 52 * kMs, middle).displacement_m[2], 0.0015, 1e-12);  // half
  EXPECT_NEAR(tracker.Update(tip, 102 * kMs, middle).displacement_m[2], 0.003, 1e-15);  // all
}

TEST(ContactTracker, ATipThatJumpsIsCaughtUpWithFromTheNodesOwnPath) {
  // A press at 30 mm/s whose input stalls for 9 ms and comes back 0.27 mm on: the node does not
  // jump there in one period; it goes on at its speed and catches up over kCatchUp_ns.
  ContactTracker tracker(CubeBox(), 0.1);
  const LatticeIndex middle{6, 6, 0};
  tracker.Update({0.125, 0.125, -0.0001}, 0, middle);
  double z = 0, previous = 0, previous_step = 0, largest_change = 0;
  std::int64_t t = 0;
  for (int n = 1; n <= 200; ++n) {
    t = n * kMs;
    z = 3e-5 * n;
    const bool stalled = n > 100 && n <= 109;  // the tip the resampler holds
    const double tip_z = stalled ? 3e-5 * 103 : z;
    const double d = tracker.Update({0.125, 0.125, tip_z}, t, middle).displacement_m[2];
    if (n > 2) largest_change = std::max(largest_change, std::abs((d - previous) - previous_step));
    previous_step = d - previous;
    previous = d;
  }
  EXPECT_NEAR(previous, z, 1e-12);  // caught up
  // The node's per-period step changed by at most a fraction of the 0.24 mm jump: no spike.
  EXPECT_LT(largest_change, 40e-6);
}

TEST(ContactTracker, AJumpOfAFewPeriodsAfterAShortHoldIsCaughtUpWithToo) {
  // As measured on a loaded machine: a press at 14 µm per period, the resampler's prediction
  // exhausted and the tip held for 3 periods, then the late inputs arrive and the tip is 49 µm
  // on in one period. Rendered as it came, that jump was a 0.2 N spike on a 1.4 N press; the node
  // catches up instead, its per-period step never changing by more than a few µm.
  ContactTracker tracker(CubeBox(), 0.1);
  const LatticeIndex middle{6, 6, 0};
  tracker.Update({0.125, 0.125, -0.0001}, 0, middle);
  double previous = 0, previous_step = 0, largest_change = 0, z = 0;
  for (int n = 1; n <= 100; ++n) {
    z = 14e-6 * n;
    const bool held = n > 50 && n <= 53;
    const double tip_z = held ? 14e-6 * 50.5 : z;  // predicted half a period on, then held
    const double d = tracker.Update({0.125, 0.125, tip_z}, n * kMs, middle).displacement_m[2];
    if (n > 2) largest_change = std::max(largest_change, std::abs((d - previous) - previous_step));
    previous_step = d - previous;
    previous = d;
  }
  EXPECT_NEAR(previous, z, 1e-12);   // caught up
  EXPECT_LT(largest_change, 15e-6);  // the hold itself stops a 14 µm step; no 48 µm jump
}

TEST(ContactTracker, AFastTouchDownAndATouchAgainFollowTheTipWithoutACatchUp) {
  // 0.1 m/s, 100 µm per period, in and out and in again: a step that is steady is no jump, and
  // a new touch starts from rest, not with the last contact's velocity.
  ContactTracker tracker(CubeBox(), 0.1);
  const LatticeIndex middle{6, 6, 0};
  std::int64_t t = 0;
  for (int touch = 0; touch < 2; ++touch) {
    for (int n = -2; n <= 4; ++n) {
      const double z = 1e-4 * n + 0.5e-4;  // first inside at 50 µm
      const auto c = tracker.Update({0.125, 0.125, z}, t += kMs, middle);
      if (z > 0) {
        EXPECT_NEAR(c.displacement_m[2], z, 1e-15) << touch << " " << n;
      }
    }
    for (int n = 4; n >= -2; --n)
      tracker.Update({0.125, 0.125, 1e-4 * n - 0.5e-4}, t += kMs, middle);
  }
}

TEST(ContactTracker, ADeepTouchDownRampsInFromZero) {
  // A session that begins with the tool 1 cm inside (or a tip that jumped in): no step.
  ContactTracker tracker(CubeBox(), 0.1);
  const LatticeIndex middle{6, 6, 0};
  tracker.Update({0.125, 0.125, -0.001}, 0, middle);
  const std::array<double, 3> tip{0.125, 0.125, 0.01};
  const auto touch = tracker.Update(tip, kMs, middle);
  EXPECT_TRUE(touch.engaged);
  EXPECT_EQ(touch.displacement_m[2], 0.0);
  EXPECT_EQ(touch.inward_normal, (std::array<double, 3>{0, 0, 1}));
  EXPECT_NEAR(tracker.Update(tip, 51 * kMs, middle).displacement_m[2], 0.005, 1e-12);
  EXPECT_NEAR(tracker.Update(tip, 101 * kMs, middle).displacement_m[2], 0.01, 1e-15);
}

// A touch at x (by the cube's side edge, y = 0.125) on `node`, 3 mm in over 30 periods and held
// for 30; the time of the last period.
std::int64_t PressThreeMillimetresIn(ContactTracker& tracker, double x, const LatticeIndex& node) {
  tracker.Update({x, 0.125, -0.001}, 0, node);
  std::int64_t t = 0;
  for (int n = 1; n <= 60; ++n) tracker.Update({x, 0.125, 1e-4 * std::min(n, 30)}, t += kMs, node);
  return t;
}

// A tip that goes off the object sideways while pressed in (here past the cube's side edge, 3 mm
// deep; on a curved object over a step of its voxel staircase) lets the node go back to rest over
// kSlipOff_ns, in contact meanwhile, instead of dropping it in one period; one going straight out
// lets go at once (ATouchOnTheCentredNode…: from 4 mm in to 1 mm out).
TEST(ContactTracker, ATipThatGoesOffSidewaysPressedInLetsTheNodeGoBackToRestSmoothly) {
  ContactTracker tracker(CubeBox(), 0.1);
  const LatticeIndex edge{12, 6, 0};  // on the side edge x = 0.25
  std::int64_t t = PressThreeMillimetresIn(tracker, 0.2495, edge);
  // Sideways at 5 mm/s (a step of 5 µm a period: no jump to catch up with), 3 mm deep: out of
  // the cube after 100 periods.
  double previous = 0.003, previous_step = 0, largest_change = 0;
  int engaged_outside = 0;
  bool released = false;
  for (int n = 1; n <= 200 && !released; ++n) {
    const std::array<double, 3> tip{0.2495 + 5e-6 * n, 0.125, 0.003};
    const ContactTracker::Contact c = tracker.Update(tip, t += kMs, edge);
    if (!c.engaged) {
      released = true;
      largest_change = std::max(largest_change, std::abs(0.0 - previous - previous_step));
      break;
    }
    if (tip[0] > 0.25) ++engaged_outside;
    const double d = c.displacement_m[2];
    largest_change = std::max(largest_change, std::abs((d - previous) - previous_step));
    previous_step = d - previous;
    previous = d;
  }
  ASSERT_TRUE(released) << "still engaged 200 periods on";
  EXPECT_NEAR(engaged_outside, ContactTracker::kSlipOff_ns / kMs, 1);
  EXPECT_LT(previous, 1e-5) << "let go away from rest";
  // Its per-period step into the object changed by at most a few per cent of the 3 mm it let go
  // of (smoothstep over 20 periods: 3 mm · 6/20² = 45 µm); at once it would be all 3 mm.
  EXPECT_LT(largest_change, 60e-6);
  EXPECT_TRUE(tracker.outside());
}

// Back inside while its node slips off, but nearest to another node (on the organ: the next step
// of its staircase), the tip starts a new contact once the old node is back at rest. Taken up
// again, the old node was driven by the tip less its entry point millimetres away: on the organ,
// 0.38 N sideways for 150 ms at the port guard's ceiling, and a 0.5 N step.
TEST(ContactTracker, BackInsideElsewhereWhileSlippingOffIsANewTouchOnceTheNodeIsAtRest) {
  ContactTracker tracker(CubeBox(), 0.1);
  const LatticeIndex edge{12, 6, 0};  // on the side edge x = 0.25
  std::int64_t t = PressThreeMillimetresIn(tracker, 0.2495, edge);
  std::vector<double> depth;        // the node's, from the last period inside on
  for (int n = 1; n <= 102; ++n) {  // sideways at 5 mm/s, out over the edge: the node slips off
    const auto c = tracker.Update({0.2495 + 5e-6 * n, 0.125, 0.003}, t += kMs, edge);
    if (n >= 100) depth.push_back(c.displacement_m[2]);
  }
  // In again two nodes back (41.7 mm away), 0.2 mm deep, and held there.
  const std::array<double, 3> elsewhere{0.2083, 0.125, 0.0002};
  ContactTracker::Contact c = tracker.Update(elsewhere, t += kMs, edge);
  for (; c.engaged; c = tracker.Update(elsewhere, t += kMs, edge)) {
    depth.push_back(c.displacement_m[2]);
    ASSERT_LE(depth.size(), ContactTracker::kSlipOff_ns / kMs + 4) << "the old node never let go";
  }
  depth.push_back(0);  // let go
  // Slipping from period 101 (the tip past x = 0.25) until let go: the first entry is inside, the
  // last the let-go.
  EXPECT_GE(depth.size() - 2, ContactTracker::kSlipOff_ns / kMs - 1);
  EXPECT_LT(depth[depth.size() - 2], 1e-5) << "the old node let go away from rest";
  // As in a slip-off alone (ATipThatGoesOffSidewaysPressedIn…): its per-period step changed by at
  // most 3 mm · 6/20² = 45 µm; taken up again from 42 mm away, by millimetres.
  double largest_change = 0;
  for (std::size_t k = 2; k < depth.size(); ++k) {
    largest_change = std::max(largest_change, std::abs(depth[k] - 2 * depth[k - 1] + depth[k - 2]));
  }
  EXPECT_LT(largest_change, 60e-6);
  // Then the new touch: on its own node, which the regions are not centred on.
  EXPECT_TRUE(c.waiting);
  EXPECT_EQ(tracker.wanted_node(), (LatticeIndex{10, 6, 0}));
}

TEST(ContactTracker, BackInsideWhileSlippingOffTheNodeCatchesUpWithTheTipAgain) {
  ContactTracker tracker(CubeBox(), 0.1);
  const LatticeIndex edge{12, 6, 0};
  std::int64_t t = PressThreeMillimetresIn(tracker, 0.2497, edge);
  // Sideways at 5 mm/s, out over the edge for 9 periods, then back in along the same line.
  double previous = 0.003, previous_step = 0, largest_change = 0, d = 0;
  double shallowest = 0.003;
  int outside = 0;
  for (int n = 1; n <= 200; ++n) {
    const double x = 0.2497 + 5e-6 * (n <= 65 ? n : std::max(0, 130 - n));
    outside += x > 0.25;
    const ContactTracker::Contact c = tracker.Update({x, 0.125, 0.003}, t += kMs, edge);
    ASSERT_TRUE(c.engaged) << n;
    d = c.displacement_m[2];
    shallowest = std::min(shallowest, d);
    if (n > 1) largest_change = std::max(largest_change, std::abs((d - previous) - previous_step));
    previous_step = d - previous;
    previous = d;
  }
  EXPECT_EQ(outside, 9);
  EXPECT_NEAR(d, 0.003, 1e-12) << "back with the tip";
  // Turned back from going to rest to the tip within kCatchUp_ns: a larger change of step than
  // letting go alone makes, but no step (let go at once, the node would have dropped all 3 mm in
  // one period, and touched again ramped in from zero).
  std::printf(
      "back inside: the node let go of %.2f mm; %.1f µm most change of its step between periods\n",
      (0.003 - shallowest) * 1e3, largest_change * 1e6);
  EXPECT_LT(largest_change, 200e-6);
}

// Input that stops while the node slips off holds it; back (still outside), the slip goes on
// from where it was held instead of jumping to where its ramp's clock got to.
TEST(ContactTracker, AGapWhileSlippingOffGoesOnFromWhereTheNodeWasHeld) {
  ContactTracker tracker(CubeBox(), 0.1);
  const LatticeIndex edge{12, 6, 0};
  std::int64_t t = PressThreeMillimetresIn(tracker, 0.2495, edge);
  std::array<double, 3> tip{};
  double d = 0.003;
  for (int n = 1; n <= 105; ++n) {  // out of the cube from the 101st period: 5 periods slipping
    tip = {0.2495 + 5e-6 * n, 0.125, 0.003};
    d = tracker.Update(tip, t += kMs, edge).displacement_m[2];
  }
  ASSERT_GT(tip[0], 0.25);
  for (int n = 0; n < 30; ++n) {  // a 30 ms gap: longer than the slip itself
    const ContactTracker::Contact held = tracker.Hold(t += kMs, edge);
    ASSERT_TRUE(held.engaged);
    EXPECT_EQ(held.displacement_m[2], d);
  }
  const ContactTracker::Contact back = tracker.Update(tip, t += kMs, edge);
  ASSERT_TRUE(back.engaged) << "the slip went on";
  EXPECT_NEAR(back.displacement_m[2], d, 1e-9) << "from where it was held";
  bool released = false;
  for (int n = 0; n < 40 && !released; ++n) {
    released = !tracker.Update(tip, t += kMs, edge).engaged;
  }
  EXPECT_TRUE(released);
}

TEST(ContactTracker, InputBackAfterAGapRampsFromTheHeldDisplacement) {
  ContactTracker tracker(CubeBox(), 0.1);
  const LatticeIndex middle{6, 6, 0};
  tracker.Update({0.125, 0.125, -0.0001}, 0, middle);
  for (int n = 1; n <= 40; ++n) tracker.Update({0.125, 0.125, 1e-4 * n}, n * kMs, middle);
  // Stale: the node holds 4 mm in whatever the time.
  EXPECT_NEAR(tracker.Hold(100 * kMs, middle).displacement_m[2], 0.004, 1e-15);
  EXPECT_NEAR(tracker.Hold(600 * kMs, middle).displacement_m[2], 0.004, 1e-15);
  // The device is back with the tool 8 mm in: from 4 mm to 8 mm over the ramp, not at once.
  const std::array<double, 3> tip{0.125, 0.125, 0.008};
  EXPECT_NEAR(tracker.Update(tip, 601 * kMs, middle).displacement_m[2], 0.004, 1e-15);
  EXPECT_NEAR(tracker.Update(tip, 651 * kMs, middle).displacement_m[2], 0.006, 1e-12);
  EXPECT_NEAR(tracker.Update(tip, 701 * kMs, middle).displacement_m[2], 0.008, 1e-15);
  // Through the back face the inward normal is −z.
  ContactTracker back(CubeBox(), 0.1);
  back.Update({0.125, 0.125, kEdge + 0.0001}, 0, middle);
  EXPECT_EQ(back.Update({0.125, 0.125, kEdge - 0.0001}, kMs, LatticeIndex{6, 6, 12}).inward_normal,
            (std::array<double, 3>{0, 0, -1}));
}

TEST(ContactTracker, AMispredictedTouchDownNeverPullsTheNodeOutOfTheObject) {
  // As measured beside two busy threads: the tool comes down at 1 m/s (−1 mm, then on the surface
  // in one device period) and starts the paper's press there, 1 cm at 1 Hz. The two inputs after
  // the touch-down come 1.4 ms late, so the resampler predicts the tip on at 1 m/s, 0.35 mm in
  // here (0.32 mm measured), and the next tips are under a µm in (2 µm measured). The node
  // jumped in and back; the catch-up that followed went on at the velocity of that way back and
  // pulled the node 2.3 mm out of the object while the tool pressed. A tool only pushes: the
  // node's depth is never negative, and it is back on the tip.
  InputResampler resampler(1e-3, 10e-3);
  ContactTracker tracker(CubeBox(), 0.1);
  const LatticeIndex middle{6, 6, 0};
  auto press_z = [](std::int64_t seq) {
    return seq < 100 ? -0.001 : 0.005 * (1 - std::cos(2 * M_PI * (seq - 100) * 1e-3));
  };
  auto received_ns = [](std::int64_t seq) {
    return seq * kMs + (seq == 101 || seq == 102 ? 1'400'000 : 50'000);
  };
  double touch_down_depth = -1, shallowest = 1, largest_step_change = 0, previous = 0;
  double previous_step = 0, lag = 0;
  std::int64_t next_seq = 0;
  for (std::int64_t k = 0; k < 200; ++k) {
    const std::int64_t release = k * kMs + 400'000;  // our period, 0.35 ms after an on-time input
    while (received_ns(next_seq) <= release) {
      resampler.Add(next_seq, received_ns(next_seq), {0.125, 0.125, press_z(next_seq)});
      ++next_seq;
    }
    const std::array<double, 3> tip = resampler.TipAt(release);
    const ContactTracker::Contact contact = tracker.Update(tip, release, middle);
    if (!contact.engaged) continue;
    const double d = contact.displacement_m[2];
    if (touch_down_depth < 0) touch_down_depth = tip[2];
    shallowest = std::min(shallowest, d);
    EXPECT_NEAR(contact.point_m[2], d, 1e-15);  // the port guard's contact point: on the node
    // After the mispredicted touch-down itself (in 0.35 mm and back: what the tip did):
    if (k > 105) {
      largest_step_change = std::max(largest_step_change, std::abs(d - previous - previous_step));
    }
    previous_step = d - previous;
    previous = d;
    // Caught up within the catch-up's 20 ms from the jump found at input 103 (and held since).
    if (k >= 125) lag = std::max(lag, std::abs(tip[2] - d));
  }
  // Mispredicted, yet shallower than a deep touch-down (which ramps in from zero instead).
  ASSERT_GT(touch_down_depth, 0.25e-3) << "the resampler did not mispredict the touch-down";
  ASSERT_LT(touch_down_depth, ContactTracker::kDeepTouchDown_m);
  EXPECT_GE(shallowest, 0.0) << "the node was pulled out of the object";
  EXPECT_LT(lag, 1e-12) << "not caught up with the tip within the catch-up";
  // The node's way back from the mispredicted depth is smooth: no period's step differs from the
  // last by more than a few µm (a 10 µm change is 40 mN at the node's 4 kN/m over a period).
  EXPECT_LT(largest_step_change, 5e-6);
  std::printf("predicted touch-down depth %.0f µm; shallowest node %.2f µm; step change %.2f µm\n",
              touch_down_depth * 1e6, shallowest * 1e6, largest_step_change * 1e6);
}

}  // namespace
}  // namespace hapticsim
