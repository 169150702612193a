// The error map on an object that is not the cube: a block with a notch cut out of one edge, of
// one material, held on its back face. The sweep runs the same regions and reference as on the
// cube, so what holds there must hold here: at spacing factor 1 and equal rates the regions are
// the reference (round-off only); the amplitude axis derived from linearity is the one run; a
// larger primary is closer to the reference. Where the grid names a node the object has no
// surface at, the sweep refuses, saying why. (Objects of several materials:
// material_contrast_test.cpp.)
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <string>

#include "core/error.hpp"
#include "core/errormap/error_sweep.hpp"
#include "core/scene/scene_model.hpp"
#include "tests/support/voxel_scene.hpp"

namespace hapticsim {
namespace {

constexpr double kH = 0.01;                       // voxel edge, m
constexpr std::array<int, 3> kVoxels{11, 9, 10};  // 11 and 9 intervals: k = 2 does not divide
constexpr int kLod = static_cast<int>(MapAxis::kSecondaryLod);
constexpr int kSize = static_cast<int>(MapAxis::kPrimarySize);
constexpr int kRate = static_cast<int>(MapAxis::kSecondaryRate);
constexpr int kAmplitude = static_cast<int>(MapAxis::kAmplitude);

// 0 in the notch (an edge cut away through z), 1 elsewhere.
int NotchedBlockLabel(int x, int y, int) { return x >= 8 && y >= 6 ? 0 : 1; }

// Pressed 2 mm at 2 Hz on the front-most node of the middle column, the back face held.
Scene NotchedBlock() {
  Scene scene = testing::VoxelScene(kVoxels[0], kVoxels[1], kVoxels[2], kH, NotchedBlockLabel);
  testing::HoldPlaneZ(&scene, kH * kVoxels[2]);
  scene.input.amplitude_m = 0.002;
  scene.input.frequency_hz = 2;
  return scene;
}

// The scene's own point on every axis but the configuration's.
SweepGrid Grid(std::vector<double> lods, std::vector<double> sizes, std::vector<double> rates) {
  SweepGrid grid;
  grid.name = "notched block";
  const MapPoint base = PointOfScene(NotchedBlock());
  for (int a = 0; a < kNumMapAxes; ++a) grid.axes[a] = {base[a]};
  grid.axes[kLod] = std::move(lods);
  grid.axes[kSize] = std::move(sizes);
  grid.axes[kRate] = std::move(rates);
  return grid;
}

ErrorMap Sweep(const SweepGrid& grid, SweepOptions options = {}) {
  SweepStats stats;
  return RunSweep(NotchedBlock(), grid, options, &stats);
}

TEST(ErrorMapOnAnObject, ItsContactAxesAreTheObjectsOwnContactNode) {
  const Scene scene = NotchedBlock();
  const SceneObject object = DescribeSceneObject(scene);
  const MapPoint point = PointOfScene(scene);
  const std::array<int, 3> node = object.grid.NodeIndices(object.contact_node);
  for (int c = 0; c < 3; ++c) {
    EXPECT_EQ(point[static_cast<int>(MapAxis::kContactNodeX) + c], node[c]);
  }
  EXPECT_EQ(node[2], 0) << "the front-most node of its column";
}

TEST(ErrorMapOnAnObject, EqualRatesAtFullResolutionReproduceTheReference) {
  const ErrorMap map = Sweep(Grid({1}, {1, 2}, {1000}));
  ASSERT_EQ(map.samples.size(), 2u);
  for (const MapSample& s : map.samples) {
    ASSERT_EQ(s.status, SampleStatus::kOk);
    EXPECT_GT(s.reference_peak_n, 0);
    EXPECT_LT(s.l2_percent, 1e-6);  // monolithic central difference: round-off only
  }
}

TEST(ErrorMapOnAnObject, ALargerPrimaryIsCloserAndTheAmplitudeAxisIsLinear) {
  SweepGrid grid = Grid({2}, {1, 2, 3}, {1000});
  grid.axes[kAmplitude] = {0.001, 0.002};
  SweepOptions run_all;
  run_all.use_linearity = false;
  const ErrorMap derived = Sweep(grid), ran = Sweep(grid, run_all);
  ASSERT_EQ(derived.samples.size(), 6u);
  for (size_t i = 0; i < derived.samples.size(); ++i) {
    const MapSample &x = derived.samples[i], &y = ran.samples[i];
    ASSERT_EQ(x.status, SampleStatus::kOk);
    ASSERT_EQ(y.status, SampleStatus::kOk);
    EXPECT_NEAR(x.l2_percent, y.l2_percent, 1e-9 * y.l2_percent + 1e-12);
    EXPECT_NEAR(x.reference_peak_n, y.reference_peak_n, 1e-12 * y.reference_peak_n);
  }
  // The error at each primary size (the same at either amplitude).
  std::array<double, 3> l2{};
  for (const MapSample& s : derived.samples) {
    l2[static_cast<size_t>(s.point[kSize]) - 1] = s.l2_percent;
  }
  EXPECT_GT(l2[0], l2[1]);
  EXPECT_GT(l2[1], l2[2]);
  EXPECT_GT(l2[2], 0);
  std::printf(
      "notched block, k 2, in step: relative L2 %.3f %% (r 1), %.3f %% (r 2), %.3f %% (r 3)\n",
      l2[0], l2[1], l2[2]);
}

TEST(ErrorMapOnAnObject, ANodeTheObjectHasNoSurfaceAtIsRefusedSayingSo) {
  SweepGrid grid = Grid({2}, {2}, {1000});
  grid.axes[static_cast<int>(MapAxis::kContactNodeX)] = {10};  // inside the notch, off the block
  grid.axes[static_cast<int>(MapAxis::kContactNodeY)] = {8};
  grid.axes[static_cast<int>(MapAxis::kContactNodeZ)] = {5};
  try {
    Sweep(grid);
    FAIL() << "a node in the notch was swept";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("(10, 8, 5) is not on the object's surface"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace hapticsim
