#include "core/stability_estimate.hpp"

#include <cmath>
#include <cstdint>

#include <Eigen/Eigenvalues>

#include "core/hex8_element.hpp"

namespace hapticsim {

double ElementBoundCriticalDt(const ElasticModel& model) {
  const double h = model.grid().spacing();
  const Hex8Element::Matrix24 ke = Hex8Element::Stiffness(h, model.material());
  const double lambda_ke = Eigen::SelfAdjointEigenSolver<Hex8Element::Matrix24>(
                               ke, Eigen::EigenvaluesOnly)
                               .eigenvalues()
                               .maxCoeff();
  const double element_node_mass = model.material().density_kg_m3 * h * h * h / 8.0;
  return 2.0 / std::sqrt(lambda_ke / element_node_mass);
}

StabilityEstimate EstimateStability(const ElasticModel& model,
                                    const PowerIterationOptions& options) {
  const Eigen::Index n = model.grid().num_dofs();
  // D = M^(-1/2) on free DOFs, 0 on constrained ones: A = D K D is symmetric and has the
  // eigenvalues of M⁻¹K on the free DOFs (plus zeros).
  const Eigen::VectorXd scale =
      model.free_mask().cwiseProduct(model.dof_mass().cwiseSqrt().cwiseInverse());

  // Deterministic start with every mode present: a hash-based sign pattern.
  Eigen::VectorXd x(n);
  std::uint64_t state = 0x9E3779B97F4A7C15ull;
  for (Eigen::Index i = 0; i < n; ++i) {
    state ^= state << 13;
    state ^= state >> 7;
    state ^= state << 17;
    x[i] = ((state >> 11) * 0x1.0p-53 - 0.5) * model.free_mask()[i];
  }
  x.normalize();

  Eigen::VectorXd scaled(n), ax(n);
  StabilityEstimate estimate;
  std::vector<double> history;
  history.reserve(static_cast<size_t>(options.max_iterations) + 1);
  double rayleigh = 0.0;
  for (int it = 1; it <= options.max_iterations; ++it) {
    scaled = scale.cwiseProduct(x);
    model.stiffness().Apply(scaled, ax);
    ax = scale.cwiseProduct(ax);
    rayleigh = x.dot(ax);  // x is unit length
    history.push_back(rayleigh);
    estimate.iterations = it;
    const double norm = ax.norm();
    if (!(norm > 0)) break;
    x = ax / norm;
    if (it > options.window) {
      const double earlier = history[static_cast<size_t>(it - 1 - options.window)];
      if (rayleigh - earlier <= options.relative_tolerance * rayleigh) {
        estimate.converged = true;
        break;
      }
    }
  }
  estimate.omega_max_rad_s = std::sqrt(std::max(rayleigh, 0.0));
  estimate.critical_dt_s = estimate.omega_max_rad_s > 0 ? 2.0 / estimate.omega_max_rad_s
                                                        : INFINITY;
  estimate.element_bound_dt_s = ElementBoundCriticalDt(model);
  return estimate;
}

}  // namespace hapticsim
