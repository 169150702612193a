// The error map's material-contrast axis on an object of two materials: a block of soft tissue
// (label 1) with a stiffer inclusion (label 2) one voxel under the pressed node, its back face
// held. The axis is a view of the scene's [[material]] tables (the base is the lowest label, the
// contrast the stiffest other's E over the base's), so a map point is a scene and back; what the
// map records along it is checked against what must hold whatever the code: at contrast 1 an
// inclusion that differs from the tissue only in E is the tissue, so its samples are the
// one-material block's; a stiffer inclusion makes the reference press harder, but less than
// stiffening everything would (the force of a prescribed press is monotone in the stiffness of
// any part of the body); and scaling E and ρ of the base together scales every material, so the
// sweep's similarity saving stays exact.
#include "core/scene/material_contrast.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.hpp"
#include "core/errormap/error_sweep.hpp"
#include "core/errormap/sweep_grid.hpp"
#include "core/scene/label_materials.hpp"
#include "tests/support/voxel_scene.hpp"

namespace hapticsim {
namespace {

constexpr double kH = 0.01;  // voxel edge, m
constexpr int kContrast = static_cast<int>(MapAxis::kMaterialContrast);
constexpr int kE = static_cast<int>(MapAxis::kYoungsModulus);
constexpr int kDensity = static_cast<int>(MapAxis::kDensity);

// 8 × 8 × 6 voxels; the inclusion is the 2 × 2 × 2 voxels behind the middle of the front face,
// one voxel deep (the pressed node, (4, 4, 0), is on tissue over it).
int InclusionLabel(int x, int y, int z) {
  return x >= 3 && x < 5 && y >= 3 && y < 5 && z >= 1 && z < 3 ? 2 : 1;
}

Material Tissue() {
  Material m;
  m.youngs_modulus_pa = 10e3;
  m.poisson_ratio = 0.45;
  m.density_kg_m3 = 1000;
  m.damping_per_s = 10;
  return m;
}

// The block with its inclusion `contrast` times stiffer and, unless `only_stiffer`, of its own
// ν, density and damping.
Scene BlockWithInclusion(double contrast, bool only_stiffer = false) {
  Scene scene = testing::VoxelScene(8, 8, 6, kH, InclusionLabel);
  testing::HoldPlaneZ(&scene, 6 * kH);
  Material inclusion = Tissue();
  inclusion.youngs_modulus_pa *= contrast;
  if (!only_stiffer) {
    inclusion.poisson_ratio = 0.4;
    inclusion.density_kg_m3 = 1100;
    inclusion.damping_per_s = 15;
  }
  scene.materials = {{2, inclusion}, {1, Tissue()}};  // out of label order on purpose
  scene.input.amplitude_m = 0.002;
  scene.input.frequency_hz = 2;
  return scene;
}

// The same block as one material: the tissue's (of Young's modulus `e_pa`), everywhere.
Scene OneMaterialBlock(double e_pa = Tissue().youngs_modulus_pa) {
  Scene scene = testing::VoxelScene(8, 8, 6, kH, [](int, int, int) { return 1; });
  testing::HoldPlaneZ(&scene, 6 * kH);
  scene.material = Tissue();
  scene.material.youngs_modulus_pa = e_pa;
  scene.input.amplitude_m = 0.002;
  scene.input.frequency_hz = 2;
  return scene;
}

// A grid of the scene's own point but for `changes` (axis → values), spacing factor 2, primary
// size 2, the secondary in step.
SweepGrid Grid(const Scene& scene, std::vector<std::pair<int, std::vector<double>>> changes) {
  SweepGrid grid;
  grid.name = "block with inclusion";
  const MapPoint own = PointOfScene(scene);
  for (int a = 0; a < kNumMapAxes; ++a) grid.axes[a] = {own[a]};
  grid.axes[static_cast<int>(MapAxis::kSecondaryLod)] = {2};
  grid.axes[static_cast<int>(MapAxis::kPrimarySize)] = {2};
  grid.axes[static_cast<int>(MapAxis::kSecondaryRate)] = {1000};
  for (auto& [axis, values] : changes) grid.axes[axis] = std::move(values);
  return grid;
}

// The sample whose point has `value` on `axis` (and, with `axis2`, `value2` on that), asserted
// to be computed.
const MapSample& SampleAt(const ErrorMap& map, int axis, double value, int axis2 = -1,
                          double value2 = 0) {
  const auto found = std::find_if(map.samples.begin(), map.samples.end(), [&](const MapSample& s) {
    return s.point[axis] == value && (axis2 < 0 || s.point[axis2] == value2);
  });
  EXPECT_NE(found, map.samples.end());
  EXPECT_EQ(found->status, SampleStatus::kOk);
  return *found;
}

double Relative(double a, double b) { return std::abs(a - b) / std::max(std::abs(b), 1e-300); }

TEST(MaterialContrast, IsTheStiffestOtherMaterialOverTheLowestLabel) {
  const Scene scene = BlockWithInclusion(6);
  const MapPoint point = PointOfScene(scene);
  EXPECT_DOUBLE_EQ(point[kContrast], 6);
  EXPECT_EQ(point[kE], Tissue().youngs_modulus_pa) << "the base is label 1, the table listed last";
  EXPECT_EQ(point[static_cast<int>(MapAxis::kPoissonRatio)], Tissue().poisson_ratio);
  EXPECT_EQ(PointOfScene(OneMaterialBlock())[kContrast], 1);
  // A softer inclusion: a contrast below 1. The quick grid spans 1 and the scene's contrast.
  EXPECT_DOUBLE_EQ(PointOfScene(BlockWithInclusion(0.5))[kContrast], 0.5);
  EXPECT_EQ(QuickGrid(scene).axes[kContrast], (std::vector<double>{1, 6}));
  EXPECT_EQ(QuickGrid(BlockWithInclusion(0.5)).axes[kContrast], (std::vector<double>{0.5, 1}));
  EXPECT_EQ(QuickGrid(OneMaterialBlock()).axes[kContrast], (std::vector<double>{1}));
}

TEST(MaterialContrast, APointIsTheSceneAndMovesTheOtherMaterialsWithTheBase) {
  const Scene scene = BlockWithInclusion(6);
  MapPoint point = PointOfScene(scene);
  const Scene same = SceneAtPoint(scene, point);
  for (std::size_t t = 0; t < scene.materials.size(); ++t) {
    const Material& a = same.materials[t].material;
    const Material& b = scene.materials[t].material;
    EXPECT_LT(Relative(a.youngs_modulus_pa, b.youngs_modulus_pa), 1e-15);
    EXPECT_EQ(a.poisson_ratio, b.poisson_ratio);
    EXPECT_LT(Relative(a.density_kg_m3, b.density_kg_m3), 1e-15);
    EXPECT_LT(Relative(a.damping_per_s, b.damping_per_s), 1e-15);
  }
  // Base twice as stiff and half as dense, contrast 3: the inclusion keeps its ν and its ratios
  // of density and damping to the base.
  point[kE] = 20e3;
  point[kDensity] = 500;
  point[kContrast] = 3;
  const Scene moved = SceneAtPoint(scene, point);
  EXPECT_EQ(PointOfScene(moved)[kContrast], 3);
  const Material& inclusion = moved.materials[0].material;  // label 2
  EXPECT_DOUBLE_EQ(inclusion.youngs_modulus_pa, 60e3);
  EXPECT_EQ(inclusion.poisson_ratio, 0.4);
  EXPECT_DOUBLE_EQ(inclusion.density_kg_m3, 550);
  EXPECT_DOUBLE_EQ(inclusion.damping_per_s, 15);
  EXPECT_EQ(moved.materials[1].material.youngs_modulus_pa, 20e3);
  // A base without damping: the others keep their own.
  Scene undamped = scene;
  undamped.materials[1].material.damping_per_s = 0;
  point[static_cast<int>(MapAxis::kDamping)] = 30;
  EXPECT_EQ(SceneAtPoint(undamped, point).materials[0].material.damping_per_s, 15);
}

// Equal materials are one to the regions, so a point must give equal materials exactly, not to
// an ulp: an inclusion that differs only in E, at contrast 1, on a base of E 7 kPa (7000 × 3 / 3
// is not 7000 in doubles, done naively).
TEST(MaterialContrast, AtContrastOneTheStiffestIsTheBaseExactly) {
  const Scene scene = BlockWithInclusion(3, true);
  MapPoint point = PointOfScene(scene);
  for (double e : {7e3, 11e3, 13.3e3}) {
    point[kE] = e;
    point[kContrast] = 1;
    const Scene at = SceneAtPoint(scene, point);
    EXPECT_EQ(at.materials[0].material.youngs_modulus_pa, e);
    EXPECT_EQ(IndexLabelMaterials(at).materials.size(), 1u) << "E " << e;
  }
}

TEST(MaterialContrast, OnAnObjectOfOneMaterialOnlyContrastOneExists) {
  const Scene scene = OneMaterialBlock();
  MapPoint point = PointOfScene(scene);
  EXPECT_NO_THROW(SceneAtPoint(scene, point));
  point[kContrast] = 2;
  try {
    SceneAtPoint(scene, point);
    FAIL() << "a contrast of 2 was made on one material";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("needs an object of several materials"), std::string::npos)
        << e.what();
  }
  SweepStats stats;
  try {
    RunSweep(scene, Grid(scene, {{kContrast, {1, 2}}}), {}, &stats);
    FAIL() << "a sweep over contrasts ran on one material";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("material contrast = 2.0 needs an object of several"),
              std::string::npos)
        << e.what();
  }
}

TEST(MaterialContrast, AtContrastOneTheMapIsTheOneMaterialObjects) {
  // Swept at a base of E 7 kPa: the inclusion (3 × stiffer in the scene, otherwise the tissue)
  // is the tissue at contrast 1.
  SweepStats stats;
  const Scene two = BlockWithInclusion(3, true);
  const ErrorMap map = RunSweep(two, Grid(two, {{kContrast, {1, 3}}, {kE, {7e3}}}), {}, &stats);
  const ErrorMap one = RunSweep(OneMaterialBlock(7e3), Grid(OneMaterialBlock(7e3), {}), {}, &stats);
  ASSERT_EQ(one.samples.size(), 1u);
  ASSERT_EQ(one.samples[0].status, SampleStatus::kOk);
  const MapSample& at_one = SampleAt(map, kContrast, 1);
  EXPECT_LT(Relative(at_one.reference_peak_n, one.samples[0].reference_peak_n), 1e-9);
  EXPECT_LT(Relative(at_one.l2_percent, one.samples[0].l2_percent), 1e-9);
  EXPECT_LT(Relative(at_one.max_magnitude_percent, one.samples[0].max_magnitude_percent), 1e-9);
  EXPECT_GT(SampleAt(map, kContrast, 3).reference_peak_n, at_one.reference_peak_n * 1.01);
}

TEST(MaterialContrast, AStifferInclusionPressesHarderButLessThanStiffeningEverything) {
  const Scene scene = BlockWithInclusion(6);
  SweepStats stats;
  const ErrorMap map = RunSweep(scene, Grid(scene, {{kContrast, {1, 3, 9}}}), {}, &stats);
  const double f1 = SampleAt(map, kContrast, 1).reference_peak_n;
  const double f3 = SampleAt(map, kContrast, 3).reference_peak_n;
  const double f9 = SampleAt(map, kContrast, 9).reference_peak_n;
  std::printf("reference peak force at contrast 1, 3, 9: %.4f, %.4f, %.4f N\n", f1, f3, f9);
  EXPECT_GT(f3, f1 * 1.01);
  EXPECT_GT(f9, f3 * 1.01);
  EXPECT_LT(f3, 3 * f1);
  EXPECT_LT(f9, 3 * f3);
  for (const MapSample& s : map.samples) {
    EXPECT_GT(s.l2_percent, 0) << "the regions at spacing factor 2 are not the reference";
    EXPECT_LT(s.l2_percent, 50);
  }
}

TEST(MaterialContrast, SimilarityInEOverDensityHoldsForEveryMaterial) {
  const Scene scene = BlockWithInclusion(6);
  // Per contrast, E 10 kPa at ρ 1000 is E 5 kPa at ρ 500 scaled; across contrasts nothing is.
  const SweepGrid grid =
      Grid(scene, {{kE, {5e3, 10e3}}, {kDensity, {500, 1000}}, {kContrast, {3, 6}}});
  SweepStats saved, all;
  const ErrorMap similar = RunSweep(scene, grid, {}, &saved);
  SweepOptions no_similarity;
  no_similarity.use_similarity = false;
  const ErrorMap run = RunSweep(scene, grid, no_similarity, &all);
  EXPECT_EQ(saved.saved_by_similarity, 2u);
  EXPECT_EQ(all.saved_by_similarity, 0u);
  ASSERT_EQ(similar.samples.size(), run.samples.size());
  for (std::size_t i = 0; i < run.samples.size(); ++i) {
    ASSERT_EQ(run.samples[i].status, SampleStatus::kOk);
    EXPECT_LT(Relative(similar.samples[i].reference_peak_n, run.samples[i].reference_peak_n), 1e-9);
    EXPECT_LT(Relative(similar.samples[i].l2_percent, run.samples[i].l2_percent), 1e-6);
  }
}

}  // namespace
}  // namespace hapticsim
