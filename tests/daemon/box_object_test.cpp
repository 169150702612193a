// hapticsimd on an object other than the paper's cube: a block of 10 × 6 × 4 voxels (a box whose
// node counts differ on every axis) read as a geometry, held on its back face. What the daemon
// takes from the object's lattice — which node a touch drives, what is inside, the workspace the
// input guard allows, the node codes between threads and the ids on the wire — and a press on
// the block's top face, played through the real primary period, against the static solution.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/fem/static_solver.hpp"
#include "core/scene/scene_model.hpp"
#include "daemon/contact_object.hpp"
#include "daemon/contact_tracker.hpp"
#include "daemon/haptic_loop.hpp"
#include "daemon/input_guard.hpp"
#include "tests/support/play_device.hpp"
#include "tests/support/voxel_scene.hpp"

namespace hapticsim {
namespace {

constexpr double kH = 0.01;                      // voxel edge, m
constexpr std::array<int, 3> kVoxels{10, 6, 4};  // 11 × 7 × 5 nodes: 10 × 6 × 4 cm

Scene Block(const std::function<int(int, int, int)>& label = [](int, int, int) { return 1; }) {
  Scene scene = testing::VoxelScene(kVoxels[0], kVoxels[1], kVoxels[2], kH, label);
  testing::HoldPlaneZ(&scene, kH * kVoxels[2]);  // the back face, z = 4 cm
  scene.materials = {{1, Material{}}};           // 10 kPa, ν 0.45, 1000 kg/m³, d 10/s
  scene.adaptivity.primary_size = 2;
  scene.adaptivity.secondary_lod = 1;  // the full-resolution lattice: only the rates differ
  scene.adaptivity.secondary_rate_hz = 1000;
  return scene;
}

TEST(ContactObject, IsTheObjectsLatticeWithItsHeldNodesLeftOut) {
  const ContactObject box = ContactObject::Of(Block());
  EXPECT_EQ(box.nodes(), (std::array<int, 3>{11, 7, 5}));
  EXPECT_DOUBLE_EQ(box.spacing_m(), kH);
  EXPECT_NEAR(box.extent_m()[0], 0.10, 1e-15);
  EXPECT_NEAR(box.extent_m()[1], 0.06, 1e-15);
  EXPECT_NEAR(box.extent_m()[2], 0.04, 1e-15);
  EXPECT_TRUE(box.Drivable({5, 3, 0}));    // the front face
  EXPECT_TRUE(box.Drivable({10, 6, 3}));   // a far corner, off the back face
  EXPECT_FALSE(box.Drivable({5, 3, 4}));   // the back face: held
  EXPECT_FALSE(box.Drivable({5, 3, 2}));   // inside
  EXPECT_FALSE(box.Drivable({11, 3, 0}));  // outside the lattice

  // A node's code goes between threads as one integer and comes back; every node has its own.
  std::vector<std::int64_t> codes;
  for (int x = 0; x < 11; ++x)
    for (int y = 0; y < 7; ++y)
      for (int z = 0; z < 5; ++z) {
        codes.push_back(box.Code({x, y, z}));
        ASSERT_EQ(box.Decode(codes.back()), (LatticeIndex{x, y, z}));
      }
  std::sort(codes.begin(), codes.end());
  EXPECT_EQ(std::unique(codes.begin(), codes.end()), codes.end());
}

TEST(ContactObject, AHeldFaceDrivesAFreeNeighbourAtItsRimAndNothingElsewhere) {
  const ContactObject box = ContactObject::Of(Block());
  // Every point of a raster over the back face (held): at its rim, the free node one spacing in
  // front of the held node the point rounds to (on the side face); inside the face, none — the
  // tool touches the support there, and no far node is driven instead.
  int rim = 0, none = 0;
  for (double x = 0; x <= 0.10; x += 0.0037) {
    for (double y = 0; y <= 0.06; y += 0.0041) {
      const std::optional<LatticeIndex> chosen = box.NearestDrivable({x, y, 0.04});
      const LatticeIndex held{static_cast<int>(std::lround(x / kH)),
                              static_cast<int>(std::lround(y / kH)), 4};
      ASSERT_FALSE(box.Drivable(held));
      if (held[0] == 0 || held[0] == 10 || held[1] == 0 || held[1] == 6) {
        ASSERT_TRUE(chosen) << x << ", " << y;
        EXPECT_EQ(*chosen, (LatticeIndex{held[0], held[1], 3})) << x << ", " << y;
        ++rim;
      } else {
        EXPECT_FALSE(chosen) << x << ", " << y;
        ++none;
      }
    }
  }
  EXPECT_GT(rim, 20);
  EXPECT_GT(none, 100);
  // On a free face the point's own node, on every face.
  EXPECT_EQ(box.NearestDrivable({0.031, 0.06, 0.019}), (LatticeIndex{3, 6, 2}));
  EXPECT_EQ(box.NearestDrivable({0.10, 0.012, 0.02}), (LatticeIndex{10, 1, 2}));
  EXPECT_EQ(box.NearestDrivable({0.07, 0.03, 0.0}), (LatticeIndex{7, 3, 0}));
}

TEST(ContactTrackerOnABox, ATouchOnTheHeldFaceRendersNothingUntilTheToolHasLeft) {
  const ContactObject box = ContactObject::Of(Block());
  ContactTracker tracker(box, 0.1);
  const std::int64_t ms = 1'000'000;
  const LatticeIndex front{5, 3, 0};
  // Behind the block, then through its back face (z = 4 cm) in the middle: the support.
  EXPECT_FALSE(tracker.Update({0.05, 0.03, 0.042}, 0, front).engaged);
  EXPECT_FALSE(tracker.wanted_node()) << "no node to move the regions to behind a held face";
  for (int n = 1; n <= 20; ++n) {
    const auto contact = tracker.Update({0.05, 0.03, 0.04 - 1e-4 * n}, n * ms, front);
    EXPECT_FALSE(contact.engaged) << n;
    EXPECT_FALSE(contact.waiting) << n;
  }
  // Round the block to the front: the front face engages as always.
  tracker.Update({0.05, 0.03, -0.002}, 30 * ms, front);
  EXPECT_EQ(tracker.wanted_node(), front);
  EXPECT_TRUE(tracker.Update({0.05, 0.03, 0.0003}, 31 * ms, front).engaged);
}

TEST(ContactObject, TheWireIdsDecodeWithOneNodeCountToTheBoxsNodes) {
  const ContactObject box = ContactObject::Of(Block());
  const int n = box.wire_nodes_per_axis();
  EXPECT_EQ(n, 11);
  const std::vector<std::int32_t> codes{static_cast<std::int32_t>(box.Code({0, 0, 0})),
                                        static_cast<std::int32_t>(box.Code({10, 6, 4})),
                                        static_cast<std::int32_t>(box.Code({3, 6, 2}))};
  std::vector<std::int32_t> wire;
  box.ToWireIds(codes, &wire);
  ASSERT_EQ(wire.size(), 3u);
  for (std::size_t i = 0; i < wire.size(); ++i) {  // as deformation_t says a reader decodes them
    const LatticeIndex decoded{wire[i] / (n * n), wire[i] / n % n, wire[i] % n};
    EXPECT_EQ(decoded, box.Decode(codes[i]));
  }
}

TEST(InputGuard, TheWorkspaceIsTheObjectsBoxOnEachAxisGrownByTheMargin) {
  InputGuard guard({0.10, 0.06, 0.04}, 0.05, 1e9);
  std::int64_t seq = 0, ns = 0;
  auto check = [&](std::array<double, 3> p) { return guard.Check(++seq, p, ns += 1'000'000); };
  EXPECT_EQ(check({0.149, 0.109, 0.089}), InputRejection::kAccepted);
  EXPECT_EQ(check({0.151, 0.05, 0.02}), InputRejection::kOutsideWorkspace);
  EXPECT_EQ(check({0.05, 0.111, 0.02}), InputRejection::kOutsideWorkspace);
  EXPECT_EQ(check({0.05, 0.05, 0.091}), InputRejection::kOutsideWorkspace);
  EXPECT_EQ(check({-0.049, -0.049, -0.049}), InputRejection::kAccepted);
}

// The top face (y = 6 cm) pressed 2 mm at node (3, 6, 2) — off the middle, on a face the cube's
// default press never touches — through hapticsimd's primary period (contact tracker, regions,
// port guard) in virtual time: the loop's regions centre there, the tracker drives that node
// straight down, and once the tissue has settled the force on the hand is the static solution's.
TEST(HapticLoopOnABox, APressOnTheTopFaceSettlesToTheStaticForce) {
  const LatticeIndex node{3, 6, 2};
  Scene scene = Block();
  scene.input.contact_node = node;
  HapticLoop loop(scene, HapticLoop::Options{});
  ASSERT_EQ(loop.centre_node(), node);
  const double x = node[0] * kH, z = node[2] * kH, top = 0.06, depth = 0.002;
  std::int64_t release = 1'000'000'000;
  ForceRecord record, last;
  auto play = [&](const std::array<double, 3>& tip, int seq) {
    testing::PlayPeriodInVirtualTime(loop, release, DeviceSample{seq, release, tip, false});
    release += 1'000'000;
    while (loop.forces().Pop(&record)) last = record;
  };
  int seq = 0;
  // Hovering 2 mm above another node of the top face: the regions are asked to go there.
  for (; seq < 20; ++seq) play({0.07, top + 0.002, 0.01}, seq);
  EXPECT_EQ(loop.wanted_contact_node(), (LatticeIndex{7, 6, 1}));
  // Above the node, then down at 10 mm/s to 2 mm and held for 1.5 s.
  for (; seq < 60; ++seq) play({x, top + 0.002, z}, seq);
  EXPECT_EQ(loop.wanted_contact_node(), node);
  for (int n = 1; seq < 60 + 1800; ++seq, ++n) {
    play({x, top - std::min(depth, 1e-5 * n), z}, seq);
  }
  ASSERT_TRUE(last.flags & force_flags::kInContact);
  EXPECT_EQ(loop.wanted_contact_node(), node);

  const SceneModel model(scene);
  const std::vector<double> driven{0.0, -depth, 0.0};
  const StaticSolution solved = SolveStatic(model.model(), driven, 1e-12);
  ASSERT_TRUE(solved.converged);
  // The force on the hand is the reaction's opposite: up, out of the top face.
  const std::array<double, 3> expected{-solved.driven_reaction[0], -solved.driven_reaction[1],
                                       -solved.driven_reaction[2]};
  std::printf("force after 1.5 s at 2 mm: (%.5f, %.5f, %.5f) N; static (%.5f, %.5f, %.5f) N\n",
              last.force_n[0], last.force_n[1], last.force_n[2], expected[0], expected[1],
              expected[2]);
  ASSERT_GT(expected[1], 0.01);
  EXPECT_NEAR(last.force_n[1], expected[1], 0.01 * expected[1]);
  for (int c : {0, 2}) EXPECT_NEAR(last.force_n[c], expected[c], 0.01 * expected[1]) << c;
}

}  // namespace
}  // namespace hapticsim
