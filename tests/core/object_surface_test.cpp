// The faces a reader draws an object with (ObjectSurfaceQuads), on the stepped block of
// tests/daemon/voxel_object_test.cpp — 10 × 6 × 4 voxels of 1 cm, the voxels x < 4, z < 2 cut
// out — against its area counted by hand, closed, wound outwards, on surface nodes only.
#include "core/scene/object_surface.hpp"

#include <gtest/gtest.h>

#include <array>
#include <map>
#include <set>
#include <utility>

#include "tests/support/voxel_scene.hpp"

namespace hapticsim {
namespace {

TEST(ObjectSurfaceQuads, AreTheSteppedBlocksFacesClosedAndWoundOutwards) {
  Scene scene =
      testing::VoxelScene(10, 6, 4, 0.01, [](int x, int, int z) { return x < 4 && z < 2 ? 0 : 1; });
  testing::HoldPlaneZ(&scene, 0.04);
  const SceneObject object = DescribeSceneObject(scene);
  const std::vector<std::int32_t> quads = ObjectSurfaceQuads(object);
  // In voxel faces: the front right of the step 6 × 6, the step's floor 4 × 6, its wall 6 × 2,
  // the left end above the step 6 × 2, the right end 6 × 4, the back 10 × 6, and the two sides
  // 10 × 4 − 4 × 2 each.
  ASSERT_EQ(quads.size(), 4u * (36 + 24 + 12 + 12 + 24 + 60 + 2 * 32));
  const int n = 11;  // the largest node count
  const auto position = [&](std::int32_t id) {
    return std::array<int, 3>{id / (n * n), id / n % n, id % n};
  };
  std::map<std::pair<std::int32_t, std::int32_t>, int> edges;
  for (std::size_t q = 0; q < quads.size(); q += 4) {
    std::array<std::array<int, 3>, 4> p{};
    for (std::size_t k = 0; k < 4; ++k) {
      p[k] = position(quads[q + k]);
      const LatticeIndex at{p[k][0], p[k][1], p[k][2]};
      ASSERT_TRUE(
          IsObjectSurfaceNode(object.grid, object.field, object.grid.Node(at[0], at[1], at[2])))
          << "corner (" << at[0] << ", " << at[1] << ", " << at[2] << ") is not a surface node";
      const std::int32_t a = quads[q + k], b = quads[q + (k + 1) % 4];
      ++edges[{std::min(a, b), std::max(a, b)}];
    }
    // The normal by the right-hand rule points from the face's centre into an empty voxel (or
    // out of the lattice): outwards.
    std::array<int, 3> u{}, v{}, normal{};
    for (int c = 0; c < 3; ++c) u[c] = p[1][c] - p[0][c], v[c] = p[3][c] - p[0][c];
    normal = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
    std::array<double, 3> outside{};  // the centre of the voxel across the face, in voxels
    for (int c = 0; c < 3; ++c) {
      outside[c] = (p[0][c] + p[2][c]) / 2.0 + 0.5 * normal[c] - (normal[c] == 0 ? 0.0 : 0.5);
    }
    const int x = static_cast<int>(outside[0]), y = static_cast<int>(outside[1]),
              z = static_cast<int>(outside[2]);
    const bool in_lattice =
        outside[0] >= 0 && outside[1] >= 0 && outside[2] >= 0 && x < 10 && y < 6 && z < 4;
    EXPECT_TRUE(!in_lattice || !object.field.occupied(object.field.Element(x, y, z)))
        << "a face wound into the object at (" << x << ", " << y << ", " << z << ")";
  }
  for (const auto& [edge, count] : edges) {
    EXPECT_EQ(count, 2) << "edge " << edge.first << "–" << edge.second << " on " << count;
  }
}

}  // namespace
}  // namespace hapticsim
