// K·u by node stencils on the bounding box against the element-by-element product it replaces:
// the same numbers on the same DOFs, for every primary region, every secondary region of fine
// elements (a box with a hole) and arbitrary sets of fine elements.
#include "core/regions/box_stiffness.hpp"

#include <gtest/gtest.h>

#include <random>

#include "core/error.hpp"
#include "core/regions/region_partition.hpp"
#include "core/scene/scene.hpp"

namespace hapticsim {
namespace {

std::vector<int> ElementsOf(const HybridMesh& mesh, RegionIndex region) {
  std::vector<int> ids;
  for (int e = 0; e < static_cast<int>(mesh.elements().size()); ++e) {
    if (mesh.elements()[static_cast<size_t>(e)].region == region) ids.push_back(e);
  }
  return ids;
}

// ‖box − element loop‖ / ‖element loop‖ on a random u, with every DOF of ku preset to 7 (the
// untouched ones must keep it).
double RelativeDifference(const HybridMesh& mesh, const Material& material,
                          const std::vector<int>& ids, const BoxStiffness& box, unsigned seed) {
  std::mt19937 random(seed);
  std::normal_distribution<double> value(0, 1e-3);
  const ElementSetStiffness elements(mesh, {material}, ids);
  EXPECT_EQ(box.touched_dofs(), elements.touched_dofs());
  Eigen::VectorXd u(mesh.num_dofs());
  for (Eigen::Index i = 0; i < u.size(); ++i) u[i] = value(random);
  Eigen::VectorXd by_box = Eigen::VectorXd::Constant(mesh.num_dofs(), 7.0);
  Eigen::VectorXd by_elements = by_box;
  box.Apply(u, by_box);
  elements.Apply(u, by_elements);
  return (by_box - by_elements).norm() / by_elements.norm();
}

TEST(BoxStiffness, GivesTheElementLoopsKuOnTheSameDofsForEveryPrimaryRegion) {
  std::mt19937 random(11);
  int boxes = 0;
  for (int nodes : {9, 13}) {
    for (int lod = 1; lod <= 3; ++lod) {
      for (int size = 1; size <= 4; ++size) {
        Scene scene;
        scene.mesh.nodes = nodes;
        scene.adaptivity.primary_size = size;
        scene.adaptivity.secondary_lod = lod;
        std::unique_ptr<RegionPartition> partition;
        try {
          partition = std::make_unique<RegionPartition>(scene);
        } catch (const Error&) {
          continue;  // a size that leaves no secondary region on this mesh
        }
        const HybridMesh& mesh = partition->mesh();
        const std::vector<int> ids = ElementsOf(mesh, kPrimaryRegion);
        const auto box = BoxStiffness::TryMake(mesh, {scene.material}, ids);
        ASSERT_NE(box, nullptr) << nodes << "³, lod " << lod << ", size " << size
                                << ": the primary region is a box of fine elements";
        ++boxes;
        EXPECT_LT(RelativeDifference(mesh, scene.material, ids, *box, random()), 1e-12)
            << nodes << "³, lod " << lod << ", size " << size << ", box " << box->box_nodes()[0]
            << "×" << box->box_nodes()[1] << "×" << box->box_nodes()[2];
        // The fast path carries the box's inside at least (an independent node leant on by no
        // hanging node is copied, not gathered).
        const auto& n = box->box_nodes();
        EXPECT_GE(box->direct_nodes(), (n[0] - 2) * (n[1] - 2) * (n[2] - 2));
        if (lod > 1) {
          EXPECT_LT(box->direct_nodes(), n[0] * n[1] * n[2]) << "hanging nodes on the box's face";
        }
      }
    }
  }
  EXPECT_GE(boxes, 20);
}

TEST(BoxStiffness, GivesTheElementLoopsKuForSecondaryRegionsOfFineElements) {
  // Spacing factor 1: each secondary region is a box with the next inner region's box as its
  // hole (open where it meets the contact face), so its nodes include every kind of corner and
  // edge of a hole.
  std::mt19937 random(12);
  int regions = 0;
  for (int nodes : {9, 13}) {
    for (int size = 1; size <= 4; ++size) {
      for (int shells : {1, 2}) {
        Scene scene;
        scene.mesh.nodes = nodes;
        scene.adaptivity.primary_size = size;
        scene.adaptivity.secondary_lod = 1;
        scene.adaptivity.secondary_regions = shells;
        std::unique_ptr<RegionPartition> partition;
        try {
          partition = std::make_unique<RegionPartition>(scene);
        } catch (const Error&) {
          continue;  // no room for that many shells
        }
        const HybridMesh& mesh = partition->mesh();
        for (int region = 1; region < partition->num_regions(); ++region) {
          const std::vector<int> ids = ElementsOf(mesh, region);
          const auto box = BoxStiffness::TryMake(mesh, {scene.material}, ids);
          ASSERT_NE(box, nullptr) << "fine elements are always accepted without a row minimum";
          ++regions;
          EXPECT_LT(RelativeDifference(mesh, scene.material, ids, *box, random()), 1e-12)
              << nodes << "³, size " << size << ", region " << region << " of " << shells;
        }
      }
    }
  }
  EXPECT_GE(regions, 15);
}

TEST(BoxStiffness, GivesTheElementLoopsKuForAnySetOfFineElements) {
  // Random subsets of a spacing-1 mesh's cells: nodes with every combination of cells around
  // them, runs cut anywhere.
  Scene scene;
  scene.mesh.nodes = 9;
  scene.adaptivity.primary_size = 2;
  scene.adaptivity.secondary_lod = 1;
  const RegionPartition partition(scene);
  const HybridMesh& mesh = partition.mesh();
  std::mt19937 random(13);
  for (double keep : {0.9, 0.6, 0.3}) {
    std::bernoulli_distribution kept(keep);
    std::vector<int> ids;
    for (int e = 0; e < static_cast<int>(mesh.elements().size()); ++e) {
      if (kept(random)) ids.push_back(e);
    }
    const auto box = BoxStiffness::TryMake(mesh, {scene.material}, ids);
    ASSERT_NE(box, nullptr);
    EXPECT_LT(RelativeDifference(mesh, scene.material, ids, *box, random()), 1e-12)
        << "keeping " << keep << " of the cells";
  }
}

TEST(BoxStiffness, RefusesCoarseElementsAnElementTwiceAndShortRows) {
  Scene scene;
  scene.adaptivity.primary_size = 3;
  const RegionPartition partition(scene);
  const HybridMesh& mesh = partition.mesh();
  std::vector<int> primary = ElementsOf(mesh, kPrimaryRegion);
  // Rows shorter than asked for: the 9 × 9 × 5 box is refused when rows of 10 are the minimum.
  ASSERT_NE(BoxStiffness::TryMake(mesh, {scene.material}, primary, 9), nullptr);
  EXPECT_EQ(BoxStiffness::TryMake(mesh, {scene.material}, primary, 10), nullptr);
  primary.push_back(primary.front());
  EXPECT_EQ(BoxStiffness::TryMake(mesh, {scene.material}, primary), nullptr) << "an element twice";
  // The secondary region at spacing factor 2: coarse elements.
  EXPECT_EQ(BoxStiffness::TryMake(mesh, {scene.material}, ElementsOf(mesh, kSecondaryRegion)),
            nullptr);
  EXPECT_EQ(BoxStiffness::TryMake(mesh, {scene.material}, {}), nullptr);
}

}  // namespace
}  // namespace hapticsim
