#include "core/fem/stability_estimate.hpp"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

#include "core/fem/assembled_stiffness.hpp"
#include "core/scene/scene_model.hpp"

namespace hapticsim {
namespace {

Scene SmallCube(int nodes, double nu = 0.45) {
  Scene scene;
  scene.mesh.nodes = nodes;
  scene.material.poisson_ratio = nu;
  return scene;
}

// ω_max² from a dense symmetric eigen-solve of M^(-1/2) K M^(-1/2) on the free DOFs: the
// independent oracle for the Lanczos estimate.
double DenseOmegaMax(const ElasticModel& model) {
  const AssembledStiffness k(model.grid(), model.field());
  const Eigen::MatrixXd dense = Eigen::MatrixXd(k.matrix());
  std::vector<int> free;
  for (int i = 0; i < model.grid().num_dofs(); ++i) {
    if (model.free_mask()[i] == 1.0) free.push_back(i);
  }
  const int n = static_cast<int>(free.size());
  Eigen::MatrixXd a(n, n);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      a(i, j) = dense(free[i], free[j]) /
                std::sqrt(model.dof_mass()[free[i]] * model.dof_mass()[free[j]]);
    }
  }
  return std::sqrt(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(a, Eigen::EigenvaluesOnly)
                       .eigenvalues()
                       .maxCoeff());
}

TEST(StabilityEstimate, LanczosMatchesDenseEigenSolve) {
  for (double nu : {0.40, 0.45, 0.49}) {
    const SceneModel cube(SmallCube(6, nu));
    const StabilityEstimate dut = EstimateStability(cube.model());
    EXPECT_TRUE(dut.converged);
    EXPECT_NEAR(dut.omega_max_rad_s, DenseOmegaMax(cube.model()), 1e-7 * dut.omega_max_rad_s)
        << "ν = " << nu;
  }
}

TEST(StabilityEstimate, ElementBoundIsNeverAboveTheLimit) {
  for (int nodes : {3, 7, 13}) {
    const SceneModel cube(SmallCube(nodes));
    const StabilityEstimate dut = EstimateStability(cube.model());
    EXPECT_LE(dut.element_bound_dt_s, dut.critical_dt_s) << nodes << " nodes";
    // …and not uselessly far below it.
    EXPECT_GT(dut.element_bound_dt_s, 0.5 * dut.critical_dt_s) << nodes << " nodes";
  }
}

TEST(StabilityEstimate, ScalesWithTheWaveSpeed) {
  // ω_max ∝ √(E/ρ): quadrupling E and doubling ρ multiplies dt_crit by √(2/4).
  Scene base = SmallCube(7);
  Scene stiff = base;
  stiff.material.youngs_modulus_pa *= 4;
  stiff.material.density_kg_m3 *= 2;
  const double dt_base = EstimateStability(SceneModel(base).model()).critical_dt_s;
  const double dt_stiff = EstimateStability(SceneModel(stiff).model()).critical_dt_s;
  EXPECT_NEAR(dt_stiff / dt_base, std::sqrt(0.5), 1e-6);
}

}  // namespace
}  // namespace hapticsim
