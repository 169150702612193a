#pragma once

#include <Eigen/Core>
#include <span>
#include <vector>

#include "core/fem/elastic_model.hpp"
#include "core/fem/region_integrator.hpp"

namespace hapticsim {

/** Outcome of one time step. Steps never throw: a failure is a status. */
enum class StepStatus {
  kOk,
  kNonFinite,     ///< a displacement became NaN or infinite
  kEnergyGrowth,  ///< the energy exceeded kEnergyGrowthFactor × (initial energy + input work)
};

/**
 * Explicit central difference for the whole object, M ü + d·M u̇ + K u = f with lumped M: the
 * one integrator (RegionIntegrator) with the object as one region — every DOF but the fixed and
 * the driven ones owned, those two prescribed, no load; a DOF off an object's shape (no mass) is
 * neither and stays at rest — per DOF
 *
 *   u⁺ = [dt²/m·(f − (K u)) + 2u − (1 − d·dt/2)·u⁻] / (1 + d·dt/2).
 *
 * Fixed DOFs are held at zero, driven DOFs take the values passed to Step(). The reaction at a
 * driven DOF — the force the device must apply to the object to hold the prescribed motion — is
 * the residual of the same equation at time tₙ (RegionIntegrator::PrescribedReaction):
 *
 *   R = (K u)ₙ + m·(u⁺ − 2u + u⁻)/dt² + d·m·(u⁺ − u⁻)/(2dt).
 *
 * The force felt by the user is −R.
 *
 * What this adds to the region's step is the whole object's divergence watch, every step: a
 * non-finite energy (a NaN or ∞ anywhere spreads into it) and energy growth. A damped body
 * driven at its contact can never hold more energy than it started with plus the work the
 * device did on it (passivity), so a positive-definite energy that exceeds that budget by
 * kEnergyGrowthFactor can only be a numerical instability. The factor is large because the
 * discrete energy of modes near the stability limit oscillates around the conserved one by up
 * to 1/(1 − ω²dt²/4); an instability grows geometrically and crosses it within tens to a few
 * hundred steps.
 *
 * Threads: one thread owns an integrator. Step() never allocates, locks or throws.
 */
class CentralDifferenceIntegrator {
 public:
  static constexpr double kEnergyGrowthFactor = 1e4;

  /** Sizes all workspace. The model must outlive the integrator. @pre dt_s > 0. */
  CentralDifferenceIntegrator(const ElasticModel& model, double dt_s);

  /** Rest state: u = u⁻ = 0, step counter, energy budget and input work cleared. */
  void Reset();
  /** Starts from the displacements u at tₙ and u⁻ at tₙ₋₁ (e.g. for free-decay tests). */
  void SetState(const Eigen::VectorXd& u, const Eigen::VectorXd& u_previous);

  /**
   * Advances from tₙ to tₙ₊₁ = tₙ + dt.
   * @param driven_next displacement of each driven DOF at tₙ₊₁, m, in
   *        model().constraints().driven_dofs order.
   */
  StepStatus Step(std::span<const double> driven_next) noexcept;

  /** Reaction at each driven DOF at the start time tₙ of the last step, N. */
  std::span<const double> driven_reaction() const {
    return {driven_reaction_.data(), driven_reaction_.size()};
  }
  /** ½|uₙ − uₙ₋₁|²_M/dt² + ½ uₙᵀ K uₙ at the start of the last step, J. */
  double energy() const { return energy_; }
  /** Current displacement uₙ (after the last step), m. */
  const Eigen::VectorXd& displacement() const { return region_.u(); }
  double dt() const { return dt_; }
  const ElasticModel& model() const { return model_; }

 private:
  const ElasticModel& model_;
  double dt_;
  RegionIntegrator region_;  // the object as one region: fixed, then driven DOFs prescribed
  std::vector<double> prescribed_next_;  // zeros for the fixed DOFs, then the driven values
  std::vector<double> driven_reaction_;
  std::vector<double> driven_before_;  // the driven DOFs' uₙ₋₁, for the input work
  double energy_ = 0.0;
  double energy_budget_start_ = -1.0;  // energy at the first step after Reset/SetState
  double input_work_ = 0.0;
};

}  // namespace hapticsim
