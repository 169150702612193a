#pragma once

#include <Eigen/Core>
#include <span>
#include <vector>

#include "core/fem/elastic_model.hpp"

namespace hapticsim {

struct StaticSolution {
  Eigen::VectorXd displacement;         ///< u, m (all DOFs)
  std::vector<double> driven_reaction;  ///< (K u) at each driven DOF, N
  int iterations = 0;
  double relative_residual = 0;  ///< ‖r‖/‖b‖ on the free DOFs at exit
  bool converged = false;
};

/**
 * Static equilibrium K u = f for the prescribed-displacement problem: fixed DOFs at 0, driven
 * DOFs at `driven_values`, no load on free DOFs. Solves K_ff u_f = −K_fp u_p by conjugate
 * gradients with a Jacobi preconditioner, matrix-free. The reaction at a driven DOF is the force
 * that must act there to hold the prescribed displacement.
 */
StaticSolution SolveStatic(const ElasticModel& model, std::span<const double> driven_values,
                           double relative_tolerance = 1e-10, int max_iterations = 0);

}  // namespace hapticsim
