#include "core/fem/region_integrator.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace hapticsim {

RegionIntegrator::RegionIntegrator(const StiffnessOperator& stiffness,
                                   const Eigen::VectorXd& dof_mass,
                                   const Eigen::VectorXd& dof_damping, std::vector<int> owned,
                                   std::vector<int> prescribed, std::vector<int> loaded,
                                   double substep_s)
    : stiffness_(stiffness),
      mass_(dof_mass),
      damping_(dof_damping),
      owned_(std::move(owned)),
      prescribed_(std::move(prescribed)),
      loaded_(std::move(loaded)),
      h_(substep_s),
      prescribed_reaction_(prescribed_.size(), 0.0),
      prescribed_work_(prescribed_.size(), 0.0),
      controlled_(loaded_) {
  const Eigen::Index n = stiffness.num_dofs();
  assert(damping_.size() == n && mass_.size() == n);
  for (auto& b : buffers_) b = Eigen::VectorXd::Zero(n);
  u_previous_ = &buffers_[0];
  u_ = &buffers_[1];
  u_next_ = &buffers_[2];
  ku_ = Eigen::VectorXd::Zero(n);
  external_ = Eigen::VectorXd::Zero(n);
  // h²/m per owned DOF, computed once: the same quotient Step used to divide out every step.
  step_over_mass_.reserve(owned_.size());
  for (int i : owned_) step_over_mass_.push_back(h_ * h_ / mass_[i]);
  PrecomputeDamping();
  SetControlledDofs(controlled_);
  loaded_compliance_.reserve(loaded_.size());
  for (int i : loaded_) loaded_compliance_.push_back(h_ * h_ / (mass_[i] * Plus(i)));
  end_of_step_load_.assign(loaded_.size(), 0.0);
}

RegionIntegrator::RegionIntegrator(const StiffnessOperator& stiffness,
                                   const Eigen::VectorXd& dof_mass, double damping_per_s,
                                   std::vector<int> owned, std::vector<int> prescribed,
                                   std::vector<int> loaded, double substep_s)
    : RegionIntegrator(stiffness, dof_mass,
                       Eigen::VectorXd::Constant(stiffness.num_dofs(), damping_per_s),
                       std::move(owned), std::move(prescribed), std::move(loaded), substep_s) {}

// Per owned DOF, the damping factors of the update, formed by the same operations the one-rate
// step formed its two scalars with: the same d gives the same factors, to the bit.
void RegionIntegrator::PrecomputeDamping() {
  minus_.reserve(owned_.size());
  inv_plus_.reserve(owned_.size());
  for (int i : owned_) {
    minus_.push_back(1.0 - damping_[i] * h_ / 2.0);
    inv_plus_.push_back(1.0 / Plus(i));
  }
  const double first = owned_.empty() ? 0.0 : damping_[owned_.front()];
  uniform_damping_ = std::all_of(owned_.begin(), owned_.end(),
                                 [&](int i) { return damping_[i] == first; });
  if (uniform_damping_) {
    damping_factor_ = first;
    damping_weight_ = mass_;
  } else {
    damping_factor_ = 1.0;
    damping_weight_ = damping_.cwiseProduct(mass_);
  }
}

void RegionIntegrator::SetControlledDofs(std::vector<int> dofs) {
  controlled_ = std::move(dofs);
  controlled_plus_ = 1.0;
  for (int i : controlled_) controlled_plus_ = std::max(controlled_plus_, Plus(i));
}

void RegionIntegrator::Reset() {
  for (auto& b : buffers_) b.setZero();
  external_.setZero();  // no load from before: NextBeforeLoads reads it
  ku_.setZero();
  ku_valid_ = true;  // K·0 = 0: no product needed (a region put to sleep is reset in 1 kHz time)
  std::fill(prescribed_reaction_.begin(), prescribed_reaction_.end(), 0.0);
  std::fill(prescribed_work_.begin(), prescribed_work_.end(), 0.0);
  load_work_ = damping_dissipated_ = controlled_dissipated_ = 0;
  load_work_refused_ = prescribed_work_refused_ = 0;
  load_scale_ = 1;
}

const Eigen::VectorXd& RegionIntegrator::Forces() noexcept {
  if (!ku_valid_) {
    stiffness_.Apply(*u_, ku_);
    ku_valid_ = true;
  }
  return ku_;
}

void RegionIntegrator::Step(std::span<const double> prescribed_next, std::span<const double> load,
                            double dissipate_j, const PortWorkLimits& limits) noexcept {
  assert(prescribed_next.size() == prescribed_.size() && load.size() == loaded_.size());
  for (size_t k = 0; k < loaded_.size(); ++k) external_[loaded_[k]] = load[k];
  const double swept = Predict();
  Finish(prescribed_next, load, swept, dissipate_j, limits);
}

void RegionIntegrator::Step(std::span<const double> prescribed_next, EndOfStepLoad& rule,
                            double dissipate_j, const PortWorkLimits& limits) noexcept {
  assert(prescribed_next.size() == prescribed_.size());
  assert(!(limits.load_work_j < INFINITY));  // the rule's load is rendered as given
  for (int i : loaded_) external_[i] = 0.0;
  double swept = Predict();
  double* next = u_next_->data();
  const double* up = u_previous_->data();
  // The rule reads the state at t + h, the prescribed DOFs (a held node under a tool) included.
  for (size_t k = 0; k < prescribed_.size(); ++k) next[prescribed_[k]] = prescribed_next[k];
  rule.Load(*u_next_, loaded_compliance_, end_of_step_load_);
  for (size_t k = 0; k < loaded_.size(); ++k) {
    const int i = loaded_[k];
    const double before = next[i] - up[i];
    next[i] += loaded_compliance_[k] * end_of_step_load_[k];
    const double after = next[i] - up[i];
    if (energy_terms_) swept += damping_weight_[i] * (after * after - before * before);
  }
  Finish(prescribed_next, end_of_step_load_, swept, dissipate_j, limits);
}

double RegionIntegrator::NextBeforeLoads(int owned_slot) noexcept {
  const Eigen::VectorXd& ku = Forces();
  const auto k = static_cast<size_t>(owned_slot);
  const int i = owned_[k];
  return (step_over_mass_[k] * (external_[i] - ku[i]) + 2.0 * (*u_)[i] -
          minus_[k] * (*u_previous_)[i]) *
         inv_plus_[k];
}

double RegionIntegrator::Predict() noexcept {
  const Eigen::VectorXd& ku = Forces();
  const double* u = u_->data();
  const double* up = u_previous_->data();
  double* next = u_next_->data();
  double swept = 0;  // Σ damping_weight_·(u⁺ − u⁻)² over the owned DOFs
  if (energy_terms_) {
    for (size_t k = 0; k < owned_.size(); ++k) {
      const int i = owned_[k];
      next[i] = (step_over_mass_[k] * (external_[i] - ku[i]) + 2.0 * u[i] - minus_[k] * up[i]) *
                inv_plus_[k];
      swept += damping_weight_[i] * (next[i] - up[i]) * (next[i] - up[i]);
    }
  } else {  // the same update, without the reduction that serialises the loop
    for (size_t k = 0; k < owned_.size(); ++k) {
      const int i = owned_[k];
      next[i] = (step_over_mass_[k] * (external_[i] - ku[i]) + 2.0 * u[i] - minus_[k] * up[i]) *
                inv_plus_[k];
    }
  }
  return swept;
}

void RegionIntegrator::Finish(std::span<const double> prescribed_next, std::span<const double> load,
                              double swept, double dissipate_j,
                              const PortWorkLimits& limits) noexcept {
  const Eigen::VectorXd& ku = Forces();
  const double h2 = h_ * h_;
  const double* u = u_->data();
  const double* up = u_previous_->data();
  double* next = u_next_->data();
  load_scale_ = 1;
  load_work_refused_ = 0;
  if (limits.load_work_j < INFINITY && !loaded_.empty()) {
    swept += LimitLoadWork(limits.load_work_j, load, next, up);
  }
  controlled_dissipated_ = 0;
  if (dissipate_j > 0 && !controlled_.empty()) swept += DampControlled(dissipate_j, next, up);
  damping_dissipated_ = damping_factor_ * swept / (4.0 * h_);
  load_work_ = 0;
  for (size_t k = 0; k < loaded_.size(); ++k) {
    const int i = loaded_[k];
    load_work_ += load_scale_ * load[k] * (next[i] - up[i]) / 2.0;
  }
  for (size_t k = 0; k < prescribed_.size(); ++k) next[prescribed_[k]] = prescribed_next[k];
  prescribed_work_refused_ = 0;
  if (limits.prescribed_work_j < INFINITY && port_prescribed_from_ < prescribed_.size()) {
    LimitPrescribedWork(limits.prescribed_work_j, ku.data(), next, up);
  }
  for (size_t k = 0; k < prescribed_.size(); ++k) {
    const int i = prescribed_[k];
    const double m = mass_[i];
    prescribed_reaction_[k] = ku[i] + m * (next[i] - 2.0 * u[i] + up[i]) / h2 +
                              damping_[i] * m * (next[i] - up[i]) / (2.0 * h_);
    prescribed_work_[k] = ku[i] * (next[i] - up[i]) / 2.0;
  }
  std::swap(u_previous_, u_);
  std::swap(u_, u_next_);
  ku_valid_ = false;
}

// The load f enters u⁺ of its DOF as c·f, c = h²/(m·b), b = 1 + d·h/2. Scaled by α, its work
// ½ Σ f·(u⁺ − u⁻) is α·B + α²·A with A = ½ Σ c f² ≥ 0 and B = W(1) − A: zero at α = 0, so the
// largest α ∈ [0, 1] with W(α) ≤ limit always exists; it is the positive root, in whichever form
// does not cancel. The controlled damping after this only shrinks the Γ motion, and with it a
// positive work. Returns the change of Σ damping_weight_·(u⁺ − u⁻)² over the loaded DOFs.
double RegionIntegrator::LimitLoadWork(double limit_j, std::span<const double> load, double* next,
                                       const double* up) noexcept {
  double work = 0, a = 0;
  for (size_t k = 0; k < loaded_.size(); ++k) {
    const int i = loaded_[k];
    work += load[k] * (next[i] - up[i]) / 2.0;
    a += h_ * h_ / (mass_[i] * Plus(i)) * load[k] * load[k] / 2.0;
  }
  const double limit = std::max(0.0, limit_j);
  if (!(work > limit)) return 0;
  const double b = work - a;
  const double root = std::sqrt(b * b + 4.0 * a * limit);
  double alpha = 0;
  if (b < 0) {
    alpha = (root - b) / (2.0 * a);  // a > 0 here: work > 0 with b < 0
  } else if (b + root > 0) {
    alpha = 2.0 * limit / (b + root);
  }
  alpha = std::clamp(alpha, 0.0, 1.0);
  double swept_change = 0;
  for (size_t k = 0; k < loaded_.size(); ++k) {
    const int i = loaded_[k];
    const double before = next[i] - up[i];
    next[i] -= (1.0 - alpha) * h_ * h_ / (mass_[i] * Plus(i)) * load[k];
    const double after = next[i] - up[i];
    swept_change += damping_weight_[i] * (after * after - before * before);
  }
  load_scale_ = alpha;
  load_work_refused_ = work - (alpha * b + alpha * alpha * a);
  return swept_change;
}

// The port's work ½ Σ g·(u⁺ − u⁻), g = (K u) on its DOFs, is linear in u⁺: taking u⁺ back
// towards u⁻ by the factor α scales it by α. Scaling (not a move along g, which would change u⁺
// less but could make it move further than it was told) keeps the port's motion within what the
// neighbour sent: the region's energy stays a sum its own limit keeps positive.
void RegionIntegrator::LimitPrescribedWork(double limit_j, const double* ku, double* next,
                                           const double* up) noexcept {
  double work = 0;
  for (size_t k = port_prescribed_from_; k < prescribed_.size(); ++k) {
    const int i = prescribed_[k];
    work += ku[i] * (next[i] - up[i]) / 2.0;
  }
  const double limit = std::max(0.0, limit_j);
  if (!(work > limit)) return;
  const double alpha = limit / work;
  for (size_t k = port_prescribed_from_; k < prescribed_.size(); ++k) {
    const int i = prescribed_[k];
    next[i] = up[i] + alpha * (next[i] - up[i]);
  }
  prescribed_work_refused_ = work - limit;
}

// Extra damping β (1/s, on the mass) on the controlled DOFs scales their u⁺ − u⁻ by
// b/(b + qβ), b = 1 + d·h/2, q = h/2, and so takes β·S·b²/(b + qβ)² out of the step, with
// S = Σ m (u⁺ − u⁻)²/(4h) at β = 0 over them. That rises with β up to β = b/q, where it is
// S·b/(4q): the most one step can take. β for E is the smaller root of β·S = e·(b + qβ)² with
// e = E/b², in the form that stays accurate as E → 0. Where the controlled DOFs' d differ, β is
// solved with the largest b: b/(b + qβ) grows with b, so each DOF then gives at most its share
// and the step takes out no more than E (DampControlledMixed says how much).
// Returns the change of Σ damping_weight_·(u⁺ − u⁻)² over those DOFs, for the material
// damping's share.
double RegionIntegrator::DampControlled(double dissipate_j, double* next,
                                        const double* up) noexcept {
  double swept = 0;
  for (int i : controlled_) swept += mass_[i] * (next[i] - up[i]) * (next[i] - up[i]);
  const double s = swept / (4.0 * h_), b = controlled_plus_, q = h_ / 2.0;
  if (!(s > 0)) return 0;
  const double e = dissipate_j / (b * b);
  // The same expression decides and goes under the root: rounding can never make it negative.
  const double discriminant = s * (s - 4.0 * e * b * q);
  double beta = b / q;
  if (discriminant > 0) {
    beta = 2.0 * e * b * b / ((s - 2.0 * e * b * q) + std::sqrt(discriminant));
  }
  if (!uniform_damping_) return DampControlledMixed(beta, q, next, up);
  const double scale = b / (b + q * beta);
  for (int i : controlled_) next[i] = up[i] + scale * (next[i] - up[i]);
  controlled_dissipated_ = beta * s * scale * scale;
  return swept * (scale * scale - 1.0);
}

// DampControlled's β applied with each DOF's own b = 1 + d·h/2.
double RegionIntegrator::DampControlledMixed(double beta, double q, double* next,
                                             const double* up) noexcept {
  double taken = 0, swept_change = 0;
  for (int i : controlled_) {
    const double b = Plus(i);
    const double scale = b / (b + q * beta);
    const double before = next[i] - up[i];
    next[i] = up[i] + scale * before;
    const double after = next[i] - up[i];
    taken += mass_[i] * after * after;
    swept_change += damping_weight_[i] * (after * after - before * before);
  }
  controlled_dissipated_ = beta * taken / (4.0 * h_);
  return swept_change;
}

double RegionIntegrator::DiscreteEnergy() noexcept { return BothEnergies().discrete_j; }

double RegionIntegrator::StateEnergy() noexcept { return BothEnergies().state_j; }

RegionIntegrator::Energies RegionIntegrator::BothEnergies() noexcept {
  const Eigen::VectorXd& ku = Forces();
  const Eigen::VectorXd& u = *u_;
  const Eigen::VectorXd& up = *u_previous_;
  double kinetic = 0, discrete_strain = 0, strain = 0;
  for (int i : owned_) {
    kinetic += mass_[i] * (u[i] - up[i]) * (u[i] - up[i]);
    discrete_strain += up[i] * ku[i];
    strain += u[i] * ku[i];
  }
  for (int i : prescribed_) {
    discrete_strain += up[i] * ku[i];
    strain += u[i] * ku[i];
  }
  kinetic *= 0.5 / (h_ * h_);
  return {kinetic + 0.5 * discrete_strain, kinetic + 0.5 * strain};
}

void RegionIntegrator::SetState(const Eigen::VectorXd& u, const Eigen::VectorXd& u_previous) {
  *u_ = u;
  *u_previous_ = u_previous;
  external_.setZero();  // a load on another state does not carry over
  ku_valid_ = false;
}

void RegionIntegrator::ScaleState(double factor) {
  *u_ *= factor;
  *u_previous_ *= factor;
  if (ku_valid_) ku_ *= factor;
}

double RegionIntegrator::OwnedStateNormSquared() const {
  double sum = 0;
  for (int i : owned_) sum += (*u_)[i] * (*u_)[i] + (*u_previous_)[i] * (*u_previous_)[i];
  return sum;
}

double RegionIntegrator::OwnedStateMaxAbs() const noexcept {
  double largest = 0;
  for (int i : owned_) {
    for (double value : {(*u_)[i], (*u_previous_)[i]}) {
      // NaN compares false: a diverged region must never look like one at rest.
      if (!(std::abs(value) <= largest)) largest = std::isnan(value) ? INFINITY : std::abs(value);
    }
  }
  return largest;
}

}  // namespace hapticsim
