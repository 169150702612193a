// RegionPartition's view of the primary's depth, which decides where the port limits act on the
// displacement exchange (AsyncRegions::PortLimited).
#include "core/regions/region_partition.hpp"

#include <gtest/gtest.h>

#include "tests/support/adaptive_scene.hpp"

namespace hapticsim {
namespace {

bool OneElementDeep(int primary_size, int lod) {
  return RegionPartition(testing::AdaptiveScene(primary_size, lod, 600)).PrimaryOneElementDeep();
}

TEST(RegionPartition, APrimaryOneElementDeepIsOneWhoseElementsAllTouchGamma) {
  EXPECT_TRUE(OneElementDeep(1, 1));   // 2 × 2 × 1 elements around the contact, each on Γ
  EXPECT_FALSE(OneElementDeep(2, 1));  // 4 × 4 × 2: the four at the contact are off Γ
  EXPECT_FALSE(OneElementDeep(3, 1));
  // At spacing factor 2 the primary box is whole coarse cells: around the middle node (6, 6, 0),
  // sizes 1 and 2 make the same regions, 4 × 4 × 2 fine elements; around a node at odd x and y
  // size 1 is one coarse cell, 2 × 2 × 2 fine elements, each on Γ.
  EXPECT_FALSE(OneElementDeep(1, 2));
  EXPECT_FALSE(OneElementDeep(2, 2));
  Scene odd = testing::AdaptiveScene(1, 2, 600);
  odd.input.contact_node = LatticeIndex{7, 7, 0};
  EXPECT_TRUE(RegionPartition(odd).PrimaryOneElementDeep());
}

}  // namespace
}  // namespace hapticsim
