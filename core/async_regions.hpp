#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "core/boundary_channel.hpp"
#include "core/contact_trajectory.hpp"
#include "core/reference_trial.hpp"
#include "core/region_integrator.hpp"
#include "core/region_partition.hpp"
#include "core/stability_estimate.hpp"

namespace hapticsim {

/** One region's schedule: its rate and how many substeps its stability limit requires. */
struct RegionSchedule {
  double rate_hz = 0;
  int substeps = 1;
  StabilityEstimate alone;  ///< the region's own limit with its boundary held
};

/** The spectral radius of the map that advances the coupled state by one common period. */
struct CoupledStability {
  double spectral_radius = 0;  ///< per common period; < 1 decays, > 1 grows
  double common_period_s = 0;  ///< 1 / gcd(rates)
  int periods = 0;             ///< periods of power iteration used
  bool stable = false;         ///< spectral_radius < kStableBelow
  /** Margin below 1 that counts as stable: a mode decaying slower than this is refused. */
  static constexpr double kStableBelow = 1.0 - 1e-6;
};

/**
 * The object solved as two asynchronous regions (see RegionPartition): the primary at the
 * primary rate 1/solver.dt, the secondary at adaptivity.secondary_rate, each with the substeps
 * its own stability limit requires, linked through two BoundaryChannels:
 *
 *   secondary → primary: Γ displacements at the secondary's step times. The primary takes Γ at
 *                        each of its substep times on the line through the newest two
 *                        (interpolation when the secondary is ahead, as the virtual-time
 *                        schedule guarantees; extrapolation if it is late).
 *   primary → secondary: the primary's forces on Γ, (K_p u)_Γ, at the primary's step times. The
 *                        secondary extrapolates them linearly to each of its substep times.
 *
 * Why this exchange (docs/regions.md): the secondary owns Γ with the mass of both sides, so at
 * equal rates the scheme is exactly monolithic central difference (k = 1 reproduces the
 * reference to round-off). With unequal rates a lagged interface force acts as negative
 * damping; extrapolating the force to the secondary's time instead of averaging or holding it
 * removes the first-order lag. Whether what remains is stable depends on the configuration, so
 * every configuration's coupled spectral radius is computed before it may run.
 *
 * StepPrimary() and StepSecondary() are the only code that advances the simulation. The
 * virtual-time schedule (RunTrial, EstimateCoupledStability) calls them in a deterministic order;
 * a real-time schedule calls them from one thread each.
 *
 * Threads: StepPrimary from one thread, StepSecondary from one (possibly other) thread; neither
 * allocates, locks or throws. Everything else: one thread, while no steps run.
 */
class AsyncRegions {
 public:
  /** Divergence: energy above this factor × (initial energy + input work), as in the reference. */
  static constexpr double kEnergyGrowthFactor = 1e4;
  /** Substeps keep each region's step at most this fraction of its own critical step. */
  static constexpr double kSubstepSafety = 0.95;

  /** What the primary sends the secondary for Γ. */
  enum class Coupling {
    kForce,         ///< the primary's Γ forces (K_p u)_Γ, extrapolated to the secondary's time
    kDisplacement,  ///< the primary's displacements next to Γ; the secondary evaluates (K_p u)_Γ
                    ///< itself with its own current Γ, so only the cross-coupling is lagged
  };

  /** @throws Error for invalid adaptivity settings. The coupling is adaptivity.coupling. */
  explicit AsyncRegions(const Scene& scene);

  const RegionPartition& partition() const { return partition_; }
  const RegionSchedule& schedule(RegionIndex region) const { return schedules_[region]; }

  /** Integer ticks of the virtual-time clock: 1 tick = 1 / ticks_per_second() s. */
  std::int64_t ticks_per_second() const { return ticks_per_second_; }
  std::int64_t period_ticks(RegionIndex region) const { return period_ticks_[region]; }
  std::int64_t common_period_ticks() const { return common_period_ticks_; }
  /** Time of each region's current state, ticks. */
  std::int64_t state_ticks(RegionIndex region) const { return state_ticks_[region]; }

  /** Zero state at t = 0 with the initial snapshots published. */
  void Reset();
  /** A reproducible random state (free DOFs), consistent on Γ, at t = 0. */
  void SetRandomState(unsigned seed);

  /**
   * Primary thread: one primary period. contact_next is the contact displacement at the end of
   * the period (m, object frame); substeps interpolate it linearly. Returns the reaction R at the
   * contact at the period's start time, N (the force on the user is −R).
   */
  std::array<double, 3> StepPrimary(const std::array<double, 3>& contact_next) noexcept;
  /** Secondary thread: one secondary period. */
  void StepSecondary() noexcept;

  /** Positive-definite energy of the coupled state (both regions), J. */
  double Energy() noexcept;
  /** Its kinetic part, ½ Σ m v² over the owned DOFs (no K·u needed), J. */
  double KineticEnergy() const noexcept;

  /** A trial of the scene's input on the virtual-time schedule. */
  TrialResult RunTrial();

  /** Spectral radius of the one-common-period map by power iteration from a random state. */
  CoupledStability EstimateCoupledStability(int burn_in_periods = 600, int window_periods = 300);

  /**
   * Free decay from a random state (no input): the coupled energy at the start and after every
   * `periods_per_checkpoint` common periods, `checkpoints` times, J.
   */
  std::vector<double> FreeDecayEnergies(int periods_per_checkpoint, int checkpoints,
                                        unsigned seed = 11);

  /** Compute time spent in each region's steps since Reset, s. */
  double compute_seconds(RegionIndex region) const { return compute_s_[region]; }

 private:
  void PublishInitialSnapshots();
  void PublishPrimarySide(double time_s) noexcept;
  void AdvanceSchedule(std::int64_t primary_target_ticks);

  RegionPartition partition_;
  Coupling coupling_;
  std::unique_ptr<ElementSetStiffness> band_stiffness_;  // primary elements touching Γ
  std::vector<int> band_layer_;  // their DOFs that are not on Γ
  Eigen::VectorXd band_u_, band_ku_;
  RegionSchedule schedules_[2];
  std::int64_t ticks_per_second_ = 0, common_period_ticks_ = 0;
  std::int64_t period_ticks_[2] = {0, 0};
  std::int64_t state_ticks_[2] = {0, 0};
  std::unique_ptr<RegionIntegrator> primary_, secondary_;
  BoundaryChannel interface_displacement_;  // secondary → primary
  BoundaryChannel interface_force_;         // primary → secondary (forces or band displacements)

  // Preallocated work space of the two step functions (each used by one thread only).
  BoundaryChannel::Snapshot displacement_newer_, displacement_older_;
  BoundaryChannel::Snapshot force_newer_, force_older_;
  std::vector<double> primary_prescribed_, secondary_prescribed_, secondary_load_;
  std::vector<double> interface_values_, force_values_;
  std::array<double, 3> contact_now_{};
  double compute_s_[2] = {0, 0};
};

}  // namespace hapticsim
