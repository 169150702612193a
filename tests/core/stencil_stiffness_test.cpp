#include "core/fem/stencil_stiffness.hpp"

#include <gtest/gtest.h>

#include "core/fem/assembled_stiffness.hpp"
#include "tests/support/random_field.hpp"

namespace hapticsim {
namespace {

struct GridCase {
  int nx, ny, nz;
};

class StencilMatchesAssembled : public ::testing::TestWithParam<GridCase> {};

TEST_P(StencilMatchesAssembled, OnRandomDisplacements) {
  const auto [nx, ny, nz] = GetParam();
  const HexGrid grid(nx, ny, nz, 0.25 / 12);
  Material material;
  material.poisson_ratio = 0.49;  // the nearly incompressible end stresses the λ couplings
  const StencilStiffness dut(grid, material);
  const AssembledStiffness oracle(grid, material);
  for (unsigned seed = 1; seed <= 3; ++seed) {
    const Eigen::VectorXd u = testing::RandomField(grid.num_dofs(), seed, 1e-3);
    Eigen::VectorXd ku_stencil(grid.num_dofs()), ku_assembled(grid.num_dofs());
    dut.Apply(u, ku_stencil);
    oracle.Apply(u, ku_assembled);
    EXPECT_LT((ku_stencil - ku_assembled).norm(), 1e-12 * ku_assembled.norm());
  }
  EXPECT_LT((dut.Diagonal() - oracle.Diagonal()).norm(), 1e-12 * oracle.Diagonal().norm());
}

// Sizes cover: the 2-node minimum (no interior), rows shorter than one vector chunk, rows with a
// chunk plus a tail (16+8+4 exact, and overlapping tails), and unequal axes (catches swapped
// strides).
INSTANTIATE_TEST_SUITE_P(Grids, StencilMatchesAssembled,
                         ::testing::Values(GridCase{2, 2, 2}, GridCase{3, 3, 3}, GridCase{5, 4, 3},
                                           GridCase{13, 13, 13}, GridCase{21, 6, 9},
                                           GridCase{2, 11, 4}, GridCase{30, 3, 3},
                                           GridCase{7, 5, 2}));

TEST(StencilStiffness, CountsTheFlopsOfTheStoredCouplings) {
  // An interior node couples to 27 neighbours: 81 diagonal-block terms and 72 off-diagonal
  // ones (x–y couplings vanish unless the neighbour is offset in both x and y, etc.).
  const HexGrid grid(3, 3, 3, 0.1);
  const StencilStiffness dut(grid, Material{});
  EXPECT_GT(dut.FlopsPerApply(), 0.0);
  EXPECT_LE(dut.FlopsPerApply(), 27.0 * 2 * 153);
}

}  // namespace
}  // namespace hapticsim
