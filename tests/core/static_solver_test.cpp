#include "core/fem/static_solver.hpp"

#include <gtest/gtest.h>

#include "core/scene/scene_model.hpp"

namespace hapticsim {
namespace {

// A block pulled along z between a roller support (u_z = 0 on z = 0) and a prescribed
// displacement δ on z = L, free to contract sideways: uniaxial stress σ_zz = E·δ/L, so the total
// reaction is E·A·δ/L — exact for trilinear hexahedra because the solution is affine.
TEST(StaticSolver, UniaxialBlockMatchesAnalyticalStiffness) {
  const double h = 0.01, delta = 2e-4;
  const HexGrid grid(4, 3, 6, h);
  DofConstraints constraints;
  std::vector<double> driven;
  for (int iy = 0; iy < grid.ny(); ++iy) {
    for (int ix = 0; ix < grid.nx(); ++ix) {
      constraints.fixed_dofs.push_back(grid.Dof(grid.Node(ix, iy, 0), 2));
      constraints.driven_dofs.push_back(grid.Dof(grid.Node(ix, iy, grid.nz() - 1), 2));
      driven.push_back(delta);
    }
  }
  // Remove the in-plane rigid motions without restraining the lateral contraction.
  constraints.fixed_dofs.push_back(grid.Dof(grid.Node(0, 0, 0), 0));
  constraints.fixed_dofs.push_back(grid.Dof(grid.Node(0, 0, 0), 1));
  constraints.fixed_dofs.push_back(grid.Dof(grid.Node(grid.nx() - 1, 0, 0), 1));
  Material material;
  material.youngs_modulus_pa = 12e3;
  material.poisson_ratio = 0.3;
  const ElasticModel model(grid, material, constraints);

  const StaticSolution solution = SolveStatic(model, driven, 1e-13);
  ASSERT_TRUE(solution.converged);
  double total = 0;
  for (double r : solution.driven_reaction) total += r;
  const double area = (grid.nx() - 1) * h * (grid.ny() - 1) * h;
  const double length = (grid.nz() - 1) * h;
  const double analytical = material.youngs_modulus_pa * area * delta / length;
  EXPECT_NEAR(total, analytical, 1e-9 * analytical);
  // And the lateral contraction is ν·δ/L per unit length.
  const int corner = grid.Node(grid.nx() - 1, 0, grid.nz() - 1);
  EXPECT_NEAR(solution.displacement[grid.Dof(corner, 0)],
              -material.poisson_ratio * delta / length * (grid.nx() - 1) * h, 1e-12);
}

TEST(StaticSolver, CubeReactionIsAlongThePressBySymmetry) {
  const SceneModel cube(Scene{});
  const std::array<double, 3> driven{0, 0, 0.01};
  const StaticSolution solution = SolveStatic(cube.model(), driven);
  ASSERT_TRUE(solution.converged);
  const auto& r = solution.driven_reaction;
  EXPECT_GT(r[2], 0.0);  // the device pushes into the object
  EXPECT_LT(std::abs(r[0]), 1e-9 * r[2]);
  EXPECT_LT(std::abs(r[1]), 1e-9 * r[2]);
}

TEST(StaticSolver, ReactionIsLinearInTheDisplacement) {
  const SceneModel cube(Scene{});
  const std::array<double, 3> small{0, 0, 0.005}, large{0, 0, 0.015};
  const double r_small = SolveStatic(cube.model(), small, 1e-12).driven_reaction[2];
  const double r_large = SolveStatic(cube.model(), large, 1e-12).driven_reaction[2];
  EXPECT_NEAR(r_large / r_small, 3.0, 1e-9);
}

}  // namespace
}  // namespace hapticsim
