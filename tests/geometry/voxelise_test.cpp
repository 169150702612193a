#include "core/geometry/voxelise.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include "core/error.hpp"
#include "tests/geometry/mesh_shapes.hpp"

namespace hapticsim {
namespace {

using test::Box;
using test::CountLabelled;

constexpr double kSpacing = 0.001;  // m; the boxes below are drawn in multiples of it

test::Vec3 InVoxels(double x, double y, double z) {
  return {x * kSpacing, y * kSpacing, z * kSpacing};
}

TEST(VoxeliseClosedSurface, TheLatticeStartsAtTheLowestCornerAndCoversTheBox) {
  const LabelVolume volume = VoxeliseClosedSurface(
      Box({0.1, 0.2, 0.3}, {0.1 + 2.2 * kSpacing, 0.2 + 3.5 * kSpacing, 0.3 + 1.4 * kSpacing}),
      kSpacing, 7 /* label */);
  EXPECT_EQ(volume.voxels, (std::array<int, 3>{3, 4, 2}));  // ceil(2.2), ceil(3.5), ceil(1.4)
  EXPECT_EQ(volume.origin_m, (std::array<double, 3>{0.1, 0.2, 0.3}));
  EXPECT_EQ(volume.spacing_m, kSpacing);
  EXPECT_NO_THROW(ValidateLabelVolume(volume));
  // Centres inside: x 0.5, 1.5 (2.5 is past 2.2) · y 0.5, 1.5, 2.5 (3.5 on the face: outside)
  // · z 0.5 (1.5 is past 1.4).
  EXPECT_EQ(CountLabelled(volume), 6u);
  EXPECT_EQ(volume.at(1, 2, 0), 7);
}

TEST(VoxeliseClosedSurface, ABoxWithFacesOnCentrePlanesIsHalfOpen) {
  // Box A fixes the origin; box B's faces lie ON planes of voxel centres (x = 2.5, 5.5;
  // y = 0.5, 3.5; z = 0.5, 2.5 voxels), its vertical edges on columns, and the diagonals of its
  // top and bottom faces through the columns (3.5, 1.5) and (4.5, 2.5): every grazing case.
  // Half-open [low, high): x 2.5, 3.5, 4.5 · y 0.5, 1.5, 2.5 · z 0.5, 1.5 → 18, + 1 for A.
  const TriangleMesh mesh = test::Joined(Box(InVoxels(0, 0, 0), InVoxels(1, 1, 1)),
                                         Box(InVoxels(2.5, 0.5, 0.5), InVoxels(5.5, 3.5, 2.5)));
  const LabelVolume volume = VoxeliseClosedSurface(mesh, kSpacing);
  EXPECT_EQ(volume.voxels, (std::array<int, 3>{6, 4, 3}));
  EXPECT_EQ(CountLabelled(volume), 19u);
  EXPECT_EQ(volume.at(0, 0, 0), 1);
  EXPECT_EQ(volume.at(2, 0, 0), 1);  // centre (2.5, 0.5, 0.5): B's lowest corner, inside
  EXPECT_EQ(volume.at(5, 3, 2), 0);  // centre (5.5, 3.5, 2.5): B's highest corner, outside
  EXPECT_EQ(volume.at(3, 1, 1), 1);  // on the diagonal of B's top and bottom faces
  EXPECT_EQ(volume.at(4, 2, 1), 1);
  // The same count with every triangle wound inwards: parity does not see orientation.
  EXPECT_EQ(VoxeliseClosedSurface(test::Flipped(mesh), kSpacing).labels, volume.labels);
}

TEST(VoxeliseClosedSurface, ABoxWithFacesOnCentrePlanesAtItsHighSideKeepsTheLowerVoxels) {
  // Faces at 2.5, 3.5, 1.5 voxels: centres on them are outside, half-open: 2 × 3 × 1.
  const LabelVolume volume =
      VoxeliseClosedSurface(Box(InVoxels(0, 0, 0), InVoxels(2.5, 3.5, 1.5)), kSpacing);
  EXPECT_EQ(volume.voxels, (std::array<int, 3>{3, 4, 2}));
  EXPECT_EQ(CountLabelled(volume), 6u);
}

TEST(VoxeliseClosedSurface, ABoxOffsetByHalfAVoxelFillsItsVoxelsExactly) {
  // B's faces on voxel boundaries: the centres inside are 3.5, 4.5, 5.5 · 1, 2, 3 (+½) · 1.5,
  // 2.5 → 3 × 3 × 2 = 18, + 1 for A.
  const TriangleMesh mesh = test::Joined(Box(InVoxels(0, 0, 0), InVoxels(1, 1, 1)),
                                         Box(InVoxels(3, 1, 1), InVoxels(6, 4, 3)));
  const LabelVolume volume = VoxeliseClosedSurface(mesh, kSpacing);
  EXPECT_EQ(volume.voxels, (std::array<int, 3>{6, 4, 3}));
  EXPECT_EQ(CountLabelled(volume), 19u);
  EXPECT_EQ(volume.at(3, 1, 1), 1);
  EXPECT_EQ(volume.at(5, 3, 2), 1);
  EXPECT_EQ(volume.at(2, 1, 1), 0);
}

TEST(VoxeliseClosedSurface, TwoDisjointBoxesAreBothFilledAndTheGapIsNot) {
  const TriangleMesh mesh = test::Joined(Box(InVoxels(0, 0, 0), InVoxels(2, 2, 2)),
                                         Box(InVoxels(5, 0, 0), InVoxels(8, 3, 1)));
  const LabelVolume volume = VoxeliseClosedSurface(mesh, kSpacing);
  EXPECT_EQ(CountLabelled(volume), 8u + 9u);
  for (int x = 2; x < 5; ++x) EXPECT_EQ(volume.at(x, 0, 0), 0) << x;
}

/// |voxel volume − polytope volume| / polytope volume of the icosphere of radius R at R/h.
double SphereVolumeError(double radius_in_voxels, double* exact_m3, double* voxel_m3) {
  const double radius = 0.02;  // m
  const TriangleMesh sphere = test::Icosphere(radius, 4 /* 5120 triangles */, {0.1, -0.2, 0.3});
  *exact_m3 = test::EnclosedVolume(sphere);
  *voxel_m3 = test::LabelledVolume(VoxeliseClosedSurface(sphere, radius / radius_in_voxels));
  return std::abs(*voxel_m3 - *exact_m3) / *exact_m3;
}

TEST(VoxeliseClosedSurface, ASphereConvergesToItsExactVolume) {
  const double bounds[][2] = {{5, 0.08}, {10, 0.03}, {20, 0.01}, {40, 0.004}};
  for (const auto& [radius_in_voxels, bound] : bounds) {
    double exact_m3 = 0, voxel_m3 = 0;
    const double error = SphereVolumeError(radius_in_voxels, &exact_m3, &voxel_m3);
    std::printf("  R/h = %2.0f: voxels %.6e m^3, exact %.6e m^3, relative error %.4f\n",
                radius_in_voxels, voxel_m3, exact_m3, error);
    EXPECT_LT(error, bound) << "R/h = " << radius_in_voxels;
  }
}

TEST(VoxeliseClosedSurface, InvertingEveryTriangleGivesTheSameVoxels) {
  const TriangleMesh sphere = test::Icosphere(0.02, 3, {0, 0, 0});
  EXPECT_EQ(VoxeliseClosedSurface(test::Flipped(sphere), 0.002).labels,
            VoxeliseClosedSurface(sphere, 0.002).labels);
  TriangleMesh half_flipped = sphere;  // inconsistent orientation: parity still does not care
  for (std::size_t t = 0; t < half_flipped.triangles.size(); t += 2) {
    std::swap(half_flipped.triangles[t][1], half_flipped.triangles[t][2]);
  }
  EXPECT_EQ(VoxeliseClosedSurface(half_flipped, 0.002).labels,
            VoxeliseClosedSurface(sphere, 0.002).labels);
}

TEST(VoxeliseClosedSurface, ATorusHasItsHoleEmpty) {
  // Major radius 30 mm, tube 10 mm: the hole is the cylinder r < 20 mm about the z axis.
  const TriangleMesh torus = test::Torus(0.03, 0.01, 64, 32, {0, 0, 0});
  const double h = 0.002;
  const LabelVolume volume = VoxeliseClosedSurface(torus, h);
  std::size_t in_hole = 0, in_tube = 0;
  for (int z = 0; z < volume.voxels[2]; ++z) {
    for (int y = 0; y < volume.voxels[1]; ++y) {
      for (int x = 0; x < volume.voxels[0]; ++x) {
        const double cx = volume.origin_m[0] + (x + 0.5) * h;
        const double cy = volume.origin_m[1] + (y + 0.5) * h;
        const double r = std::hypot(cx, cy);
        if (r < 0.019) in_hole += volume.at(x, y, z) != 0;
        if (std::abs(r - 0.03) < 0.005 && std::abs(volume.origin_m[2] + (z + 0.5) * h) < 0.005) {
          in_tube += volume.at(x, y, z) == 0;  // deep inside the tube: must be labelled
        }
      }
    }
  }
  EXPECT_EQ(in_hole, 0u);
  EXPECT_EQ(in_tube, 0u);
  const double exact = std::abs(test::EnclosedVolume(torus));
  EXPECT_NEAR(test::LabelledVolume(volume), exact, 0.03 * exact);
}

TEST(VoxeliseClosedSurface, ARotatedBoxKeepsItsVolume) {
  const TriangleMesh box = Box({0, 0, 0}, {0.04, 0.03, 0.02});
  const double pi = std::acos(-1.0);
  const TriangleMesh rotated = test::Rotated(box, pi / 6, {0.02, 0.015, 0.01});
  const double exact = 0.04 * 0.03 * 0.02;
  ASSERT_NEAR(test::EnclosedVolume(rotated), exact, 1e-15);
  const double voxelised = test::LabelledVolume(VoxeliseClosedSurface(rotated, 0.001));
  std::printf("  box rotated 30 deg about z and x, h = 1 mm: %.6e m^3 vs %.6e m^3\n", voxelised,
              exact);
  EXPECT_NEAR(voxelised, exact, 0.02 * exact);
}

TEST(VoxeliseClosedSurface, IsDeterministic) {
  const TriangleMesh mesh = test::Rotated(test::Icosphere(0.02, 3, {0.01, 0, 0}), 0.3, {0, 0, 0});
  const LabelVolume first = VoxeliseClosedSurface(mesh, 0.0015);
  const LabelVolume second = VoxeliseClosedSurface(mesh, 0.0015);
  EXPECT_EQ(first.labels, second.labels);
  EXPECT_EQ(first.origin_m, second.origin_m);
}

TEST(VoxeliseClosedSurface, RefusesBadSpacingsHugeLatticesAndOpenMeshes) {
  const TriangleMesh box = Box({0, 0, 0}, {1, 1, 1});
  for (double spacing : {0.0, -1.0, std::nan(""), std::numeric_limits<double>::infinity()}) {
    EXPECT_THROW(VoxeliseClosedSurface(box, spacing), Error) << spacing;
  }
  try {
    VoxeliseClosedSurface(box, 1e-4);  // 10^12 voxels
    ADD_FAILURE() << "no Error";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find("coarser geometry.spacing_m"), std::string::npos)
        << error.what();
  }
  EXPECT_THROW(VoxeliseClosedSurface(box, 1e-300), Error);  // a count beyond any int
  EXPECT_THROW(VoxeliseClosedSurface(box, 0.1, 0 /* label */), Error);
  TriangleMesh open = box;
  open.triangles.pop_back();
  EXPECT_THROW(VoxeliseClosedSurface(open, 0.1), Error);
}

}  // namespace
}  // namespace hapticsim
