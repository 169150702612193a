#include "core/regions/hybrid_mesh.hpp"

#include <gtest/gtest.h>

#include "core/regions/element_set_stiffness.hpp"
#include "core/error.hpp"
#include "core/fem/stencil_stiffness.hpp"
#include "tests/support/hybrid_mesh_fields.hpp"
#include "tests/support/random_field.hpp"

namespace hapticsim {
namespace {

HybridMesh::Options CubeOptions(int k, int r) {
  HybridMesh::Options o;
  o.lattice_nodes = {13, 13, 13};
  o.spacing_m = 0.25 / 12;
  o.coarse_factor = k;
  o.primary_lo = {6 - r, 6 - r, 0};
  o.primary_hi = {6 + r, 6 + r, r};
  o.supports = {{0, 0, 12}, {12, 0, 12}, {0, 12, 12}, {12, 12, 12}};
  return o;
}

using testing::AffineField;
using testing::AllElements;

TEST(HybridMesh, WithoutCoarseningIsTheFullGrid) {
  const HybridMesh dut(CubeOptions(1, 2));
  EXPECT_EQ(dut.num_independent(), 13 * 13 * 13);
  EXPECT_EQ(dut.num_hanging(), 0);
  EXPECT_EQ(dut.elements().size(), 12u * 12 * 12);
  // …and its stiffness is the stencil's.
  const ElementSetStiffness k(dut, {Material{}}, AllElements(dut));
  const HexGrid grid(13, 13, 13, 0.25 / 12);
  const StencilStiffness oracle(grid, Material{});
  const Eigen::VectorXd u = testing::RandomField(grid.num_dofs(), 3);
  // Same lexicographic lattice? Map through the lattice indices.
  Eigen::VectorXd u_mesh(dut.num_dofs());
  for (int r = 0; r < dut.num_independent(); ++r) {
    const auto& p = dut.LatticeOf(r);
    for (int c = 0; c < 3; ++c) u_mesh[dut.Dof(r, c)] = u[grid.Dof(grid.Node(p[0], p[1], p[2]), c)];
  }
  Eigen::VectorXd ku_mesh = Eigen::VectorXd::Zero(dut.num_dofs()), ku(grid.num_dofs());
  k.Apply(u_mesh, ku_mesh);
  oracle.Apply(u, ku);
  double worst = 0;
  for (int r = 0; r < dut.num_independent(); ++r) {
    const auto& p = dut.LatticeOf(r);
    for (int c = 0; c < 3; ++c) {
      worst = std::max(
          worst, std::abs(ku_mesh[dut.Dof(r, c)] - ku[grid.Dof(grid.Node(p[0], p[1], p[2]), c)]));
    }
  }
  EXPECT_LT(worst, 1e-12 * ku.cwiseAbs().maxCoeff());
}

TEST(HybridMesh, MassIsConservedAcrossHangingNodes) {
  for (int k : {2, 3}) {
    const HybridMesh dut(CubeOptions(k, 2));
    EXPECT_GT(dut.num_hanging(), 0);
    const double rho = 1000, edge = 0.25;
    Material material;
    material.density_kg_m3 = rho;
    // Each component block carries the whole mass ρL³.
    EXPECT_NEAR(dut.DofMass({material}).head(dut.num_independent()).sum(), rho * edge * edge * edge,
                1e-12);
  }
}

class PatchAcrossResolutionJumps : public ::testing::TestWithParam<int> {};

TEST_P(PatchAcrossResolutionJumps, AffineFieldLeavesNoForceInside) {
  const HybridMesh dut(CubeOptions(GetParam(), 2));
  ASSERT_GT(dut.num_hanging(), 0);
  const ElementSetStiffness k(dut, {Material{}}, AllElements(dut));
  const Eigen::VectorXd r = testing::RandomField(12, 5, 1e-2);
  const Eigen::VectorXd u = AffineField(dut, Eigen::Map<const Eigen::Matrix3d>(r.data()), r.tail<3>());
  Eigen::VectorXd ku = Eigen::VectorXd::Zero(dut.num_dofs());
  k.Apply(u, ku);
  const double scale = ku.cwiseAbs().maxCoeff();
  double worst_inside = 0;
  int inside = 0;
  for (int node = 0; node < dut.num_independent(); ++node) {
    const auto& p = dut.LatticeOf(node);
    bool on_surface = false;
    for (int a = 0; a < 3; ++a) on_surface = on_surface || p[a] == 0 || p[a] == 12;
    if (on_surface) continue;
    ++inside;
    for (int c = 0; c < 3; ++c)
      worst_inside = std::max(worst_inside, std::abs(ku[dut.Dof(node, c)]));
  }
  EXPECT_GT(inside, 0);
  EXPECT_LT(worst_inside, 1e-12 * scale);
}

INSTANTIATE_TEST_SUITE_P(CoarseFactors, PatchAcrossResolutionJumps, ::testing::Values(2, 3, 4));

TEST(HybridMesh, ACoarseFactorThatDoesNotDivideTheGridRefinesTheCellsPastItsEnd) {
  // 12 intervals, k = 5: coarse cells [0, 5], [5, 10] and [10, 15], the last partly past the end.
  const HybridMesh mesh(CubeOptions(5, 2));
  int covered = 0;
  for (const HybridElement& e : mesh.elements()) {
    covered += e.size_factor * e.size_factor * e.size_factor;
    EXPECT_TRUE(e.size_factor == 1 || e.size_factor == 5);
  }
  EXPECT_EQ(covered, 12 * 12 * 12);
  for (RegionIndex region : mesh.RegionPerLatticeCell()) EXPECT_GE(region, 0);
  EXPECT_THROW(HybridMesh(CubeOptions(0, 2)), Error);
}

}  // namespace
}  // namespace hapticsim
