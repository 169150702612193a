#include "core/fem/static_solver.hpp"

#include <cmath>

#include "core/error.hpp"

namespace hapticsim {

StaticSolution SolveStatic(const ElasticModel& model, std::span<const double> driven_values,
                           double relative_tolerance, int max_iterations) {
  const auto& constraints = model.constraints();
  HAPTICSIM_THROW_UNLESS(driven_values.size() == constraints.driven_dofs.size(),
                         "one value per driven DOF is needed");
  const Eigen::Index n = model.grid().num_dofs();
  if (max_iterations <= 0) max_iterations = static_cast<int>(10 * n);
  const Eigen::VectorXd& free = model.free_mask();
  const StiffnessOperator& k = model.stiffness();

  StaticSolution solution;
  Eigen::VectorXd u = Eigen::VectorXd::Zero(n);
  for (size_t i = 0; i < driven_values.size(); ++i) {
    u[constraints.driven_dofs[i]] = driven_values[i];
  }
  // Residual of the free equations: r = −(K u_p) on free DOFs.
  Eigen::VectorXd ku(n);
  k.Apply(u, ku);
  Eigen::VectorXd r = -ku.cwiseProduct(free);
  // (Off an object's shape the diagonal is 0 and the DOF is not free: no 0 · ∞ there.)
  const Eigen::VectorXd inv_diagonal =
      (free.array() > 0).select(k.Diagonal().cwiseInverse(), 0.0);
  const double b_norm = r.norm();

  Eigen::VectorXd z = inv_diagonal.cwiseProduct(r);
  Eigen::VectorXd p = z;
  Eigen::VectorXd kp(n);
  double rz = r.dot(z);
  int it = 0;
  double residual = b_norm > 0 ? 1.0 : 0.0;
  while (residual > relative_tolerance && it < max_iterations) {
    k.Apply(p, kp);
    kp = kp.cwiseProduct(free);
    const double alpha = rz / p.dot(kp);
    u += alpha * p;
    r -= alpha * kp;
    ++it;
    residual = r.norm() / b_norm;
    z = inv_diagonal.cwiseProduct(r);
    const double rz_next = r.dot(z);
    p = z + (rz_next / rz) * p;
    rz = rz_next;
  }

  k.Apply(u, ku);
  solution.displacement = std::move(u);
  for (int dof : constraints.driven_dofs) solution.driven_reaction.push_back(ku[dof]);
  solution.iterations = it;
  solution.relative_residual = residual;
  solution.converged = residual <= relative_tolerance;
  return solution;
}

}  // namespace hapticsim
