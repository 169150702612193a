#include "core/fem/central_difference_integrator.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <string>

#include "core/error.hpp"

namespace hapticsim {
namespace {

// Every free DOF, in order: neither fixed nor driven, and on the object (a node off an object's
// shape has no mass; it is neither stepped nor prescribed, and stays at rest).
std::vector<int> FreeDofs(const ElasticModel& model) {
  std::vector<int> free;
  for (int dof = 0; dof < model.grid().num_dofs(); ++dof) {
    if (model.free_mask()[dof] > 0) free.push_back(dof);
  }
  return free;
}

std::vector<int> FixedThenDriven(const ElasticModel& model) {
  std::vector<int> dofs = model.constraints().fixed_dofs;
  dofs.insert(dofs.end(), model.constraints().driven_dofs.begin(),
              model.constraints().driven_dofs.end());
  return dofs;
}

double CheckedStep(double dt_s) {
  HAPTICSIM_THROW_UNLESS(std::isfinite(dt_s) && dt_s > 0, "the time step must be > 0 s");
  return dt_s;
}

}  // namespace

CentralDifferenceIntegrator::CentralDifferenceIntegrator(const ElasticModel& model, double dt_s)
    : model_(model),
      dt_(CheckedStep(dt_s)),
      region_(model.stiffness(), model.dof_mass(), model.dof_damping(),
              FreeDofs(model), FixedThenDriven(model), {}, dt_s),
      prescribed_next_(region_.prescribed().size(), 0.0),
      driven_reaction_(model.constraints().driven_dofs.size(), 0.0),
      driven_before_(driven_reaction_.size(), 0.0) {
  region_.SetEnergyTerms(false);  // the divergence watch below takes the energy over every DOF
}

void CentralDifferenceIntegrator::Reset() {
  region_.Reset();
  std::fill(driven_reaction_.begin(), driven_reaction_.end(), 0.0);
  energy_ = 0.0;
  energy_budget_start_ = -1.0;
  input_work_ = 0.0;
}

void CentralDifferenceIntegrator::SetState(const Eigen::VectorXd& u,
                                           const Eigen::VectorXd& u_previous) {
  HAPTICSIM_THROW_UNLESS(u.size() == region_.u().size() && u_previous.size() == u.size(),
                         "state vectors must have one entry per DOF");
  // Off the object a DOF is never stepped: it must be at rest, or its value would stay there.
  for (Eigen::Index i = 0; i < u.size(); ++i) {
    HAPTICSIM_THROW_UNLESS(model_.dof_mass()[i] > 0 || (u[i] == 0 && u_previous[i] == 0),
                           "DOF " + std::to_string(i) + " is off the object: its state must be 0");
  }
  Reset();
  region_.SetState(u, u_previous);
}

StepStatus CentralDifferenceIntegrator::Step(std::span<const double> driven_next) noexcept {
  const size_t fixed = model_.constraints().fixed_dofs.size();
  assert(driven_next.size() == model_.constraints().driven_dofs.size());
  // The energy at tₙ over every DOF (the driven ones' motion too), from the K·u the step uses.
  const Eigen::VectorXd& ku = region_.Forces();
  const Eigen::VectorXd& u = region_.u();
  const Eigen::VectorXd& up = region_.u_previous();
  const Eigen::VectorXd& mass = model_.dof_mass();
  double kinetic_sum = 0.0;  // Σ m (u − u⁻)²
  double strain_sum = 0.0;   // Σ u (K u)
  for (Eigen::Index i = 0; i < ku.size(); ++i) {
    const double du = u[i] - up[i];
    kinetic_sum += mass[i] * du * du;
    strain_sum += u[i] * ku[i];
  }
  energy_ = 0.5 * kinetic_sum / (dt_ * dt_) + 0.5 * strain_sum;

  const std::vector<int>& driven = model_.constraints().driven_dofs;
  for (size_t k = 0; k < driven.size(); ++k) driven_before_[k] = up[driven[k]];  // uₙ₋₁
  std::copy(driven_next.begin(), driven_next.end(), prescribed_next_.begin() + fixed);
  region_.Step(prescribed_next_, {});
  for (size_t k = 0; k < driven.size(); ++k) {
    const double reaction = region_.PrescribedReaction(static_cast<int>(fixed + k));
    driven_reaction_[k] = reaction;
    const double work = reaction * (driven_next[k] - driven_before_[k]) / 2.0;
    if (work > 0) input_work_ += work;
  }

  if (!std::isfinite(energy_) || !std::isfinite(input_work_)) return StepStatus::kNonFinite;
  if (energy_budget_start_ < 0) energy_budget_start_ = energy_;
  const double budget = energy_budget_start_ + input_work_;
  if (energy_ > kEnergyGrowthFactor * budget && energy_ > 0) return StepStatus::kEnergyGrowth;
  return StepStatus::kOk;
}

}  // namespace hapticsim
