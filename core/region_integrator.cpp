#include "core/region_integrator.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace hapticsim {

RegionIntegrator::RegionIntegrator(const StiffnessOperator& stiffness,
                                   const Eigen::VectorXd& dof_mass, double damping_per_s,
                                   std::vector<int> owned, std::vector<int> prescribed,
                                   std::vector<int> loaded, double substep_s)
    : stiffness_(stiffness),
      mass_(dof_mass),
      damping_(damping_per_s),
      owned_(std::move(owned)),
      prescribed_(std::move(prescribed)),
      loaded_(std::move(loaded)),
      h_(substep_s),
      prescribed_reaction_(prescribed_.size(), 0.0) {
  const Eigen::Index n = stiffness.num_dofs();
  for (auto& b : buffers_) b = Eigen::VectorXd::Zero(n);
  u_previous_ = &buffers_[0];
  u_ = &buffers_[1];
  u_next_ = &buffers_[2];
  ku_ = Eigen::VectorXd::Zero(n);
  external_ = Eigen::VectorXd::Zero(n);
}

void RegionIntegrator::Reset() {
  for (auto& b : buffers_) b.setZero();
  ku_.setZero();
  ku_valid_ = true;  // K·0 = 0: no product needed (a region put to sleep is reset in 1 kHz time)
  std::fill(prescribed_reaction_.begin(), prescribed_reaction_.end(), 0.0);
}

const Eigen::VectorXd& RegionIntegrator::Forces() noexcept {
  if (!ku_valid_) {
    stiffness_.Apply(*u_, ku_);
    ku_valid_ = true;
  }
  return ku_;
}

void RegionIntegrator::Step(std::span<const double> prescribed_next,
                            std::span<const double> load) noexcept {
  assert(prescribed_next.size() == prescribed_.size() && load.size() == loaded_.size());
  const Eigen::VectorXd& ku = Forces();
  for (size_t k = 0; k < loaded_.size(); ++k) external_[loaded_[k]] = load[k];
  const double minus = 1.0 - damping_ * h_ / 2.0;
  const double inv_plus = 1.0 / (1.0 + damping_ * h_ / 2.0);
  const double h2 = h_ * h_;
  const double* u = u_->data();
  const double* up = u_previous_->data();
  double* next = u_next_->data();
  for (int i : owned_) {
    next[i] = (h2 / mass_[i] * (external_[i] - ku[i]) + 2.0 * u[i] - minus * up[i]) * inv_plus;
  }
  for (size_t k = 0; k < prescribed_.size(); ++k) {
    const int i = prescribed_[k];
    next[i] = prescribed_next[k];
    const double m = mass_[i];
    prescribed_reaction_[k] = ku[i] + m * (next[i] - 2.0 * u[i] + up[i]) / h2 +
                              damping_ * m * (next[i] - up[i]) / (2.0 * h_);
  }
  std::swap(u_previous_, u_);
  std::swap(u_, u_next_);
  ku_valid_ = false;
}

void RegionIntegrator::SetState(const Eigen::VectorXd& u, const Eigen::VectorXd& u_previous) {
  *u_ = u;
  *u_previous_ = u_previous;
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
