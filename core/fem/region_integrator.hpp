#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "core/fem/stiffness_operator.hpp"

namespace hapticsim {

/**
 * The most work each of the region's two ports may do on it in one step, J (≥ 0; infinity:
 * no limit). The ports are the interfaces with its neighbours: its load (the inner region's
 * force on its inner Γ) and its port prescribed DOFs (its outer Γ, SetPortPrescribedFrom).
 * A port that would do more is changed as little as it takes to do exactly the limit: the load
 * scaled down (by α ∈ [0, 1]: its work is αB + α²A with A ≥ 0, so some α always fits), the
 * prescribed values' motion u⁺ − u⁻ scaled down (work linear in it). Either way a port can
 * always be made to do no work, so a limit always holds.
 */
struct PortWorkLimits {
  double load_work_j = INFINITY;
  double prescribed_work_j = INFINITY;
};

/**
 * A load on a region's loaded DOFs that depends on where they end the step: a contact spring
 * taken implicitly (ProxyContact). An explicit spring on a node much lighter than its stiffness
 * rings at the substep rate and, being one-sided, gains energy at every bounce; one solved for the
 * step's end is dissipative and needs no substep of its own (docs/model.md).
 */
class EndOfStepLoad {
 public:
  /**
   * @param predicted   the state at t + h without this load (owned and prescribed DOFs)
   * @param compliance  per loaded DOF, how far its u⁺ moves per newton of its load, m/N:
   *                    h²/(m·(1 + d·h/2))
   * @param load        written: the load, N, in loaded() order
   * Never allocates or throws.
   */
  virtual void Load(const Eigen::VectorXd& predicted, std::span<const double> compliance,
                    std::span<double> load) noexcept = 0;

 protected:
  ~EndOfStepLoad() = default;
};

/**
 * Central difference for one region: the same per-DOF update as CentralDifferenceIntegrator,
 *
 *   u⁺ = [h²/m·(f − (K_region u)) + 2u − (1 − d·h/2)·u⁻] / (1 + d·h/2),
 *
 * applied to the DOFs the region owns, with h the region's substep and d the DOF's own
 * mass-proportional damping rate (C = diag(d·m): an object of several materials damps each
 * node by the mass-weighted rate of the elements around it, ElasticModel::dof_damping).
 * Its boundary DOFs (the other region's interface, the contact, supports) are prescribed by the
 * caller; some owned DOFs may carry an external load (the interface forces of the other region).
 *
 * The region keeps its own copy of the whole state vector, so two regions never share memory:
 * what crosses between them goes through a BoundaryChannel.
 *
 * Threads: one thread owns a region. Step() never allocates, locks or throws.
 */
class RegionIntegrator {
 public:
  /**
   * @param stiffness  K of this region's elements (writes only the DOFs they touch)
   * @param dof_mass   lumped mass of every DOF, kg (the whole object's: interface DOFs carry the
   *                   mass of both sides)
   * @param dof_damping d of every DOF in c = d·m, 1/s (ElasticModel::dof_damping). When every
   *                   owned DOF has the same d, the step is the same arithmetic, to the bit, as
   *                   the one-rate constructor's.
   * @param owned      DOFs this region updates
   * @param prescribed DOFs whose values the caller sets every substep
   * @param loaded     owned DOFs that receive an external load every substep
   */
  RegionIntegrator(const StiffnessOperator& stiffness, const Eigen::VectorXd& dof_mass,
                   const Eigen::VectorXd& dof_damping, std::vector<int> owned,
                   std::vector<int> prescribed, std::vector<int> loaded, double substep_s);
  /** One damping rate d (1/s) for every DOF (a one-material object, the uniform cube). */
  RegionIntegrator(const StiffnessOperator& stiffness, const Eigen::VectorXd& dof_mass,
                   double damping_per_s, std::vector<int> owned, std::vector<int> prescribed,
                   std::vector<int> loaded, double substep_s);

  /** Zero state. */
  void Reset();

  /** K·u of the current state (cached until the state changes). */
  const Eigen::VectorXd& Forces() noexcept;

  /**
   * One substep from t to t + h.
   * @param prescribed_next values of the prescribed DOFs at t + h, in prescribed() order
   * @param load            external force on the loaded DOFs at t, N, in loaded() order
   * @param dissipate_j     energy to take out of the controlled DOFs in this step, J: extra
   *                        damping on them, as much of it as one step can take
   *                        (ControlledDissipated() says how much it did). 0: none.
   * @param limits          the most work the ports may do in this step (PortWorkLimits)
   */
  void Step(std::span<const double> prescribed_next, std::span<const double> load,
            double dissipate_j = 0, const PortWorkLimits& limits = PortWorkLimits{}) noexcept;
  /**
   * One substep whose load the loaded DOFs' own end of step decides (EndOfStepLoad): u⁺ is formed
   * without it, `rule` gives the load from that, and the load is added to u⁺ (it enters linearly),
   * so the step satisfies the equation of motion with that load. Its work counts as a load's.
   * Extra damping asked for (`dissipate_j`) is applied after, to the state the load left: the
   * load then matches the step's end only to that damping's share. `limits` must not limit the
   * load (the rule's caller renders exactly the load it gave): load_work_j stays infinite.
   */
  void Step(std::span<const double> prescribed_next, EndOfStepLoad& rule, double dissipate_j = 0,
            const PortWorkLimits& limits = PortWorkLimits{}) noexcept;

  /** Prescribed DOFs from index `first` on (in prescribed() order) are the port that
   *  PortWorkLimits::prescribed_work_j limits; the ones before (contact, supports) never are.
   *  Default: none. */
  void SetPortPrescribedFrom(size_t first) { port_prescribed_from_ = first; }

  /*
   * The last step's terms of central difference's discrete energy balance. Multiplying the
   * equation of motion by Δ = (u⁺ − u⁻)/2 gives, exactly,
   *
   *   DiscreteEnergy() after − before = Σ_loaded f·Δ + Σ_prescribed (K u)·Δ
   *                                     − material damping − the extra damping,
   *
   * so a region's energy changes only through its load, its prescribed DOFs and its damping.
   */
  /** Σ over loaded DOFs of load·Δ, J. */
  double LoadWork() const { return load_work_; }
  /** (K u)·Δ at prescribed DOF index k, J: the work moving that DOF did on the region. */
  double PrescribedWork(int k) const { return prescribed_work_[k]; }
  /** Σ over owned DOFs of d_i·m_i·(u⁺ − u⁻)²/(4h), J (≥ 0). */
  double DampingDissipated() const { return damping_dissipated_; }
  /** Work the port limits kept the load and the port prescribed DOFs from doing in the last
   *  step, J (≥ 0): what they would have done less what they did. */
  double LoadWorkRefused() const { return load_work_refused_; }
  double PrescribedWorkRefused() const { return prescribed_work_refused_; }
  /** What the step's dissipate_j actually took out, J (≥ 0; less when one step cannot). */
  double ControlledDissipated() const { return controlled_dissipated_; }
  /**
   * Whether Step() sums the material damping's share of its energy balance (DampingDissipated;
   * default: yes; else it reads 0). Without it — a run that watches its energy another way, like
   * CentralDifferenceIntegrator — the same step costs one serial reduction over the DOFs less.
   */
  void SetEnergyTerms(bool keep) { energy_terms_ = keep; }
  /** The owned DOFs a dissipate_j damps (default: the loaded ones). */
  void SetControlledDofs(std::vector<int> dofs);
  /**
   * ½ Σ_owned m ((u − u⁻)/h)² + ½ u⁻ᵀ K u, J: the energy central difference conserves without
   * damping and load (positive while the step is within the region's own limit).
   */
  double DiscreteEnergy() noexcept;
  /**
   * ½ Σ_owned m ((u − u⁻)/h)² + ½ uᵀ K u over every DOF its elements touch, J: what the state
   * holds, positive whatever the step (K of its elements is positive semi-definite). Where the
   * region's step is well inside its limit and its prescribed DOFs move smoothly it is close to
   * DiscreteEnergy; where they do not (a region one element deep between the contact and Γ), the
   * discrete energy can be small or negative while this one is not (AsyncRegions::Runaway).
   */
  double StateEnergy() noexcept;
  struct Energies {
    double discrete_j = 0;  ///< DiscreteEnergy
    double state_j = 0;     ///< StateEnergy
  };
  /** Both in one pass over the DOFs (the real-time steps take both). */
  Energies BothEnergies() noexcept;

  /**
   * Residual of the equation of motion at prescribed DOF index `k` at the start of the last
   * step: (K u) + m·a + d·m·v (d that DOF's rate) — the force needed to hold the prescribed
   * motion, N.
   */
  double PrescribedReaction(int k) const { return prescribed_reaction_[k]; }

  const Eigen::VectorXd& u() const { return *u_; }
  const Eigen::VectorXd& u_previous() const { return *u_previous_; }
  const std::vector<int>& owned() const { return owned_; }
  /**
   * Where the next Step puts the owned DOF at `owned_slot` (its place in owned()) before any
   * controller or limit acts, a loaded DOF's load held at the last step's (none after Reset or
   * SetState): central difference from the state now, the same arithmetic to the last bit.
   * Explicit, it needs nothing else of the next step: a neighbour a step ahead reads it as this
   * region's next state (AsyncRegions::PublishOutward). Computes K·u if not yet (the next Step
   * reuses it).
   */
  double NextBeforeLoads(int owned_slot) noexcept;
  const std::vector<int>& prescribed() const { return prescribed_; }
  const std::vector<int>& loaded() const { return loaded_; }
  double substep() const { return h_; }

  /** Overwrites the state (for free-decay runs and the spectral-radius estimate). */
  void SetState(const Eigen::VectorXd& u, const Eigen::VectorXd& u_previous);
  /** Multiplies the whole state by `factor` (power iteration on the period map). */
  void ScaleState(double factor);
  /** Σ over owned DOFs of u² + u⁻², for the period-map norm. */
  double OwnedStateNormSquared() const;
  /** Largest |u| or |u⁻| over the owned DOFs, m: how far the region is from rest. */
  double OwnedStateMaxAbs() const noexcept;

 private:
  void PrecomputeDamping();
  // u⁺ of the owned DOFs from external_; returns Σ damping_weight_·(u⁺ − u⁻)² over them.
  double Predict() noexcept;
  // The rest of a step once u⁺ of the owned DOFs is formed with `load`.
  void Finish(std::span<const double> prescribed_next, std::span<const double> load, double swept,
              double dissipate_j, const PortWorkLimits& limits) noexcept;
  double DampControlled(double dissipate_j, double* next, const double* up) noexcept;
  double DampControlledMixed(double beta, double q, double* next,
                             const double* up) noexcept;
  double LimitLoadWork(double limit_j, std::span<const double> load, double* next,
                       const double* up) noexcept;
  /** 1 + d·h/2 of DOF i: the factor that divides its u⁺. */
  double Plus(int i) const noexcept { return 1.0 + damping_[i] * h_ / 2.0; }
  void LimitPrescribedWork(double limit_j, const double* ku, double* next,
                           const double* up) noexcept;

  const StiffnessOperator& stiffness_;
  const Eigen::VectorXd& mass_;
  Eigen::VectorXd damping_;  // d per DOF, 1/s
  std::vector<int> owned_, prescribed_, loaded_;
  double h_ = 0;
  std::vector<double> step_over_mass_;  // h²/m per owned DOF, in owned_ order
  std::vector<double> minus_;           // 1 − d·h/2 per owned DOF, in owned_ order
  std::vector<double> inv_plus_;        // 1/(1 + d·h/2) per owned DOF, in owned_ order
  std::vector<double> loaded_compliance_;  // h²/(m·(1 + d·h/2)) per loaded DOF, m/N
  std::vector<double> end_of_step_load_;   // what an EndOfStepLoad gave, per loaded DOF, N
  // The material damping's energy is damping_factor_ · Σ damping_weight_·(u⁺ − u⁻)²/(4h).
  // With one d over the owned DOFs: weight m, factor d, the sum the one-rate step always took
  // (bit for bit); else weight d·m, factor 1.
  bool uniform_damping_ = true;
  double damping_factor_ = 0;
  Eigen::VectorXd damping_weight_;
  double controlled_plus_ = 1;  // the largest 1 + d·h/2 over the controlled DOFs
  Eigen::VectorXd buffers_[3];
  Eigen::VectorXd* u_previous_;
  Eigen::VectorXd* u_;
  Eigen::VectorXd* u_next_;
  Eigen::VectorXd ku_;
  bool ku_valid_ = false;
  Eigen::VectorXd external_;  // load per DOF (zero except loaded DOFs)
  std::vector<double> prescribed_reaction_;
  std::vector<double> prescribed_work_;
  std::vector<int> controlled_;
  size_t port_prescribed_from_ = SIZE_MAX;
  bool energy_terms_ = true;
  double load_scale_ = 1;  // α the load limit applied in the last step
  double load_work_ = 0, damping_dissipated_ = 0, controlled_dissipated_ = 0;
  double load_work_refused_ = 0, prescribed_work_refused_ = 0;
};

}  // namespace hapticsim
