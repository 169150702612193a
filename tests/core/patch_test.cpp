// Patch test: an affine displacement field u(x) = A·x + b has uniform strain, so a conforming
// element must reproduce it exactly: no force at interior nodes, and a static solve with the
// affine values prescribed on the boundary returns the affine values inside.
#include <gtest/gtest.h>

#include "core/fem/elastic_model.hpp"
#include "core/fem/static_solver.hpp"
#include "tests/support/random_field.hpp"

namespace hapticsim {
namespace {

constexpr double kH = 0.02;

Eigen::VectorXd AffineField(const HexGrid& grid, const Eigen::Matrix3d& a,
                            const Eigen::Vector3d& b) {
  Eigen::VectorXd u(grid.num_dofs());
  for (int node = 0; node < grid.num_nodes(); ++node) {
    const auto p = grid.NodePosition(node);
    const Eigen::Vector3d value = a * Eigen::Vector3d(p[0], p[1], p[2]) + b;
    for (int c = 0; c < 3; ++c) u[grid.Dof(node, c)] = value[c];
  }
  return u;
}

bool OnBoundary(const HexGrid& grid, int node) {
  const auto [ix, iy, iz] = grid.NodeIndices(node);
  return ix == 0 || iy == 0 || iz == 0 || ix == grid.nx() - 1 || iy == grid.ny() - 1 ||
         iz == grid.nz() - 1;
}

class PatchTest : public ::testing::Test {
 protected:
  PatchTest() : grid_(5, 4, 6, kH) {
    const Eigen::VectorXd r = testing::RandomField(12, 7, 1e-2);
    a_ = Eigen::Map<const Eigen::Matrix3d>(r.data());
    b_ = r.tail<3>();
  }
  HexGrid grid_;
  Eigen::Matrix3d a_;
  Eigen::Vector3d b_;
};

TEST_F(PatchTest, AffineFieldLeavesNoForceAtInteriorNodes) {
  const ElasticModel dut(grid_, Material{}, {});
  const Eigen::VectorXd u = AffineField(grid_, a_, b_);
  Eigen::VectorXd ku(grid_.num_dofs());
  dut.stiffness().Apply(u, ku);
  const double scale = ku.cwiseAbs().maxCoeff();
  ASSERT_GT(scale, 0.0);
  for (int node = 0; node < grid_.num_nodes(); ++node) {
    if (OnBoundary(grid_, node)) continue;
    for (int c = 0; c < 3; ++c) EXPECT_LT(std::abs(ku[grid_.Dof(node, c)]), 1e-12 * scale);
  }
}

TEST_F(PatchTest, StaticSolveReproducesTheAffineFieldInside) {
  DofConstraints constraints;
  for (int node = 0; node < grid_.num_nodes(); ++node) {
    if (!OnBoundary(grid_, node)) continue;
    for (int c = 0; c < 3; ++c) constraints.driven_dofs.push_back(grid_.Dof(node, c));
  }
  Material material;
  material.poisson_ratio = 0.3;
  const ElasticModel model(grid_, material, constraints);
  const Eigen::VectorXd exact = AffineField(grid_, a_, b_);
  std::vector<double> driven;
  for (int dof : constraints.driven_dofs) driven.push_back(exact[dof]);

  const StaticSolution solution = SolveStatic(model, driven, 1e-13);
  ASSERT_TRUE(solution.converged);
  EXPECT_LT((solution.displacement - exact).cwiseAbs().maxCoeff(),
            1e-10 * exact.cwiseAbs().maxCoeff());
}

}  // namespace
}  // namespace hapticsim
