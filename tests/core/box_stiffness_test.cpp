// The primary region's K·u by the stencil on its box against the element-by-element product it
// replaces: the same numbers on the same DOFs, for every primary size and spacing factor.
#include "core/box_stiffness.hpp"

#include <gtest/gtest.h>

#include <random>

#include "core/error.hpp"
#include "core/region_partition.hpp"
#include "core/scene.hpp"

namespace hapticsim {
namespace {

std::vector<int> ElementsOf(const HybridMesh& mesh, RegionIndex region) {
  std::vector<int> ids;
  for (int e = 0; e < static_cast<int>(mesh.elements().size()); ++e) {
    if (mesh.elements()[static_cast<size_t>(e)].region == region) ids.push_back(e);
  }
  return ids;
}

TEST(BoxStiffness, GivesTheElementLoopsKuOnTheSameDofsForEveryPrimaryRegion) {
  std::mt19937 random(11);
  std::normal_distribution<double> value(0, 1e-3);
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
        const auto box = BoxStiffness::TryMake(mesh, scene.material, ids);
        ASSERT_NE(box, nullptr) << nodes << "³, lod " << lod << ", size " << size
                                << ": the primary region is a box of fine elements";
        ++boxes;
        const ElementSetStiffness elements(mesh, scene.material, ids);
        EXPECT_EQ(box->touched_dofs(), elements.touched_dofs());
        Eigen::VectorXd u(mesh.num_dofs());
        for (Eigen::Index i = 0; i < u.size(); ++i) u[i] = value(random);
        // Untouched DOFs keep what they held.
        Eigen::VectorXd by_box = Eigen::VectorXd::Constant(mesh.num_dofs(), 7.0);
        Eigen::VectorXd by_elements = by_box;
        box->Apply(u, by_box);
        elements.Apply(u, by_elements);
        EXPECT_LT((by_box - by_elements).norm(), 1e-12 * by_elements.norm())
            << nodes << "³, lod " << lod << ", size " << size << ", box " << box->box_nodes()[0]
            << "×" << box->box_nodes()[1] << "×" << box->box_nodes()[2];
      }
    }
  }
  EXPECT_GE(boxes, 20);
}

TEST(BoxStiffness, RefusesWhatIsNotAFullBoxOfFineElements) {
  Scene scene;
  scene.adaptivity.primary_size = 3;
  const RegionPartition partition(scene);
  const HybridMesh& mesh = partition.mesh();
  std::vector<int> primary = ElementsOf(mesh, kPrimaryRegion);
  // Rows shorter than asked for: the 9 × 9 × 5 box is refused when rows of 10 are the minimum.
  ASSERT_NE(BoxStiffness::TryMake(mesh, scene.material, primary, 9), nullptr);
  EXPECT_EQ(BoxStiffness::TryMake(mesh, scene.material, primary, 10), nullptr);
  primary.pop_back();  // a box with a corner missing
  EXPECT_EQ(BoxStiffness::TryMake(mesh, scene.material, primary), nullptr);
  // The secondary region: coarse elements, and a box with a hole in it.
  EXPECT_EQ(BoxStiffness::TryMake(mesh, scene.material, ElementsOf(mesh, kSecondaryRegion)),
            nullptr);
  EXPECT_EQ(BoxStiffness::TryMake(mesh, scene.material, {}), nullptr);
}

}  // namespace
}  // namespace hapticsim
