#include "core/fem/stability_estimate.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>
#include <cstdint>

#include "core/fem/hex8_element.hpp"

namespace hapticsim {

double ElementBoundCriticalDt(const ElasticModel& model) {
  // The bound of every material used; the smallest holds for all (the stiffest, lightest one's).
  const double h = model.grid().spacing();
  double critical_dt = std::numeric_limits<double>::infinity();
  const std::vector<bool> used = model.field().UsedMaterials();
  for (size_t i = 0; i < used.size(); ++i) {
    if (!used[i]) continue;
    const Material& material = model.field().materials()[i];
    const Hex8Element::Matrix24 ke = Hex8Element::Stiffness(h, material);
    const double lambda_ke =
        Eigen::SelfAdjointEigenSolver<Hex8Element::Matrix24>(ke, Eigen::EigenvaluesOnly)
            .eigenvalues()
            .maxCoeff();
    const double element_node_mass = material.density_kg_m3 * h * h * h / 8.0;
    critical_dt = std::min(critical_dt, 2.0 / std::sqrt(lambda_ke / element_node_mass));
  }
  return critical_dt;
}

StabilityEstimate EstimateStability(const ElasticModel& model,
                                    const EigenIterationOptions& options) {
  StabilityEstimate estimate =
      EstimateStability(model.stiffness(), model.dof_mass(), model.free_mask(), options);
  estimate.element_bound_dt_s = ElementBoundCriticalDt(model);
  return estimate;
}

StabilityEstimate EstimateStability(const StiffnessOperator& stiffness,
                                    const Eigen::VectorXd& dof_mass,
                                    const Eigen::VectorXd& free_mask,
                                    const EigenIterationOptions& options) {
  const Eigen::Index n = stiffness.num_dofs();
  // D = M^(-1/2) on free DOFs, 0 on constrained ones: A = D K D is symmetric and has the
  // eigenvalues of M⁻¹K on the free DOFs (plus zeros).
  // (Where free_mask is 0 the mass may be 0 too, off an object's shape: no 0 · ∞ there.)
  const Eigen::VectorXd scale =
      (free_mask.array() > 0).select(dof_mass.cwiseSqrt().cwiseInverse(), 0.0);
  Eigen::VectorXd full(n);
  auto apply_a = [&](const Eigen::VectorXd& x, Eigen::VectorXd& scratch, Eigen::VectorXd& ax) {
    scratch = scale.cwiseProduct(x);
    full.setZero();
    stiffness.Apply(scratch, full);
    ax = scale.cwiseProduct(full);
  };

  // Deterministic start with every free mode present: a hash-based pattern.
  Eigen::VectorXd q(n);
  std::uint64_t state = 0x9E3779B97F4A7C15ull;
  for (Eigen::Index i = 0; i < n; ++i) {
    state ^= state << 13;
    state ^= state >> 7;
    state ^= state << 17;
    q[i] = ((state >> 11) * 0x1.0p-53 - 0.5) * free_mask[i];
  }
  q.normalize();

  StabilityEstimate estimate;
  Eigen::VectorXd q_previous = Eigen::VectorXd::Zero(n), w(n), scratch(n);
  std::vector<double> alpha, beta;  // the tridiagonal Lanczos matrix T
  double lambda = 0.0;
  for (int j = 1; j <= options.max_iterations; ++j) {
    apply_a(q, scratch, w);
    if (!beta.empty()) w -= beta.back() * q_previous;
    alpha.push_back(q.dot(w));
    w -= alpha.back() * q;
    const double b = w.norm();
    estimate.iterations = j;

    // Check the top Ritz pair every 10 iterations (and at a breakdown or the end).
    const bool breakdown = !(b > 1e-300);
    if (j % 10 == 0 || breakdown || j == options.max_iterations) {
      const int m = static_cast<int>(alpha.size());
      Eigen::VectorXd diagonal = Eigen::Map<Eigen::VectorXd>(alpha.data(), m);
      Eigen::VectorXd sub = Eigen::VectorXd::Zero(std::max(m - 1, 0));
      for (int i = 0; i + 1 < m; ++i) sub[i] = beta[static_cast<size_t>(i)];
      Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> tridiagonal;
      tridiagonal.computeFromTridiagonal(diagonal, sub, Eigen::ComputeEigenvectors);
      const double theta = tridiagonal.eigenvalues()[m - 1];  // ascending
      const double residual =
          breakdown ? 0.0 : b * std::abs(tridiagonal.eigenvectors()(m - 1, m - 1));
      lambda = theta + residual;
      if (residual <= options.relative_tolerance * theta) {
        estimate.converged = true;
        break;
      }
    }
    if (breakdown) break;
    beta.push_back(b);
    q_previous.swap(q);
    q = w / b;
  }
  estimate.omega_max_rad_s = std::sqrt(std::max(lambda, 0.0));
  estimate.critical_dt_s = estimate.omega_max_rad_s > 0 ? 2.0 / estimate.omega_max_rad_s : INFINITY;
  return estimate;
}

}  // namespace hapticsim
