#include "core/fem/central_difference_integrator.hpp"

#include <cassert>
#include <cmath>

#include "core/error.hpp"

namespace hapticsim {

CentralDifferenceIntegrator::CentralDifferenceIntegrator(const ElasticModel& model, double dt_s)
    : model_(model), dt_(dt_s) {
  HAPTICSIM_THROW_UNLESS(std::isfinite(dt_s) && dt_s > 0, "the time step must be > 0 s");
  const int n = model.grid().num_dofs();
  const double d = model.material().damping_per_s;
  damping_minus_ = 1.0 - d * dt_ / 2.0;
  inv_damping_plus_ = 1.0 / (1.0 + d * dt_ / 2.0);
  dt2_over_mass_ = (dt_ * dt_) * model.dof_mass().cwiseInverse();
  for (auto& buffer : buffers_) buffer = Eigen::VectorXd::Zero(n);
  u_previous_ = &buffers_[0];
  u_ = &buffers_[1];
  u_next_ = &buffers_[2];
  ku_ = Eigen::VectorXd::Zero(n);
  driven_reaction_ =
      Eigen::VectorXd::Zero(static_cast<Eigen::Index>(model.constraints().driven_dofs.size()));
}

void CentralDifferenceIntegrator::Reset() {
  u_previous_->setZero();
  u_->setZero();
  driven_reaction_.setZero();
  energy_ = 0.0;
  energy_budget_start_ = -1.0;
  input_work_ = 0.0;
}

void CentralDifferenceIntegrator::SetState(const Eigen::VectorXd& u,
                                           const Eigen::VectorXd& u_previous) {
  HAPTICSIM_THROW_UNLESS(u.size() == u_->size() && u_previous.size() == u_->size(),
                         "state vectors must have one entry per DOF");
  Reset();
  *u_ = u;
  *u_previous_ = u_previous;
}

StepStatus CentralDifferenceIntegrator::Step(std::span<const double> driven_next) noexcept {
  const auto& constraints = model_.constraints();
  assert(driven_next.size() == constraints.driven_dofs.size());
  model_.stiffness().Apply(*u_, ku_);

  const Eigen::Index n = ku_.size();
  const double* ku = ku_.data();
  const double* u = u_->data();
  const double* up = u_previous_->data();
  const double* dt2m = dt2_over_mass_.data();
  const double* mass = model_.dof_mass().data();
  double* next = u_next_->data();
  double kinetic_sum = 0.0;  // Σ m (u − u⁻)²
  double strain_sum = 0.0;   // Σ u (K u)
  for (Eigen::Index i = 0; i < n; ++i) {
    next[i] = (-dt2m[i] * ku[i] + 2.0 * u[i] - damping_minus_ * up[i]) * inv_damping_plus_;
    const double du = u[i] - up[i];
    kinetic_sum += mass[i] * du * du;
    strain_sum += u[i] * ku[i];
  }
  for (int dof : constraints.fixed_dofs) next[dof] = 0.0;

  const double d = model_.material().damping_per_s;
  for (size_t k = 0; k < constraints.driven_dofs.size(); ++k) {
    const int dof = constraints.driven_dofs[k];
    next[dof] = driven_next[k];
    const double m = mass[dof];
    const double reaction = ku[dof] + m * (next[dof] - 2.0 * u[dof] + up[dof]) / (dt_ * dt_) +
                            d * m * (next[dof] - up[dof]) / (2.0 * dt_);
    driven_reaction_[static_cast<Eigen::Index>(k)] = reaction;
    const double work = reaction * (next[dof] - up[dof]) / 2.0;
    if (work > 0) input_work_ += work;
  }

  energy_ = 0.5 * kinetic_sum / (dt_ * dt_) + 0.5 * strain_sum;
  std::swap(u_previous_, u_);
  std::swap(u_, u_next_);

  if (!std::isfinite(energy_) || !std::isfinite(input_work_)) return StepStatus::kNonFinite;
  if (energy_budget_start_ < 0) energy_budget_start_ = energy_;
  const double budget = energy_budget_start_ + input_work_;
  if (energy_ > kEnergyGrowthFactor * budget && energy_ > 0) return StepStatus::kEnergyGrowth;
  return StepStatus::kOk;
}

}  // namespace hapticsim
