#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "core/fem/object_state.hpp"
#include "core/fem/region_integrator.hpp"
#include "core/fem/stability_estimate.hpp"
#include "core/regions/boundary_channel.hpp"
#include "core/regions/coupled_stability.hpp"
#include "core/regions/region_partition.hpp"
#include "core/regions/region_schedule.hpp"
#include "core/regions/stepping_order.hpp"
#include "core/scene/contact_trajectory.hpp"
#include "core/trial/reference_trial.hpp"

namespace hapticsim {

/** What the runaway watch measured when it fired (AsyncRegions::Runaway): the state's energy and
 *  what the energy balance allowed (at least the port floor), J. */
struct RunawayEnergies {
  double state_j = 0;
  double allowed_j = 0;
};

/**
 * The discrete energy balance of the coupled regions since Reset, J. Exactly (to round-off)
 *
 *   stored − stored at Reset = input work − damping dissipated + interface created
 *                              − interface dissipated.
 *
 * The interface controllers keep interface created − interface dissipated at most
 * kDampingCredit × credited damping, plus what they have not yet managed to take out, so then
 * stored ≤ stored at Reset + input work − damping + kDampingCredit × credited damping
 * (docs/regions.md, "Passive interfaces").
 */
struct EnergyAccount {
  double stored_j = 0;                ///< Σ over the regions of RegionIntegrator::DiscreteEnergy
  double input_work_j = 0;            ///< work the contact did on the object
  double damping_dissipated_j = 0;    ///< taken out by the material's damping (≥ 0)
  double credited_damping_j = 0;      ///< of which in the secondary regions (each credits its link)
  double interface_created_j = 0;     ///< net work the exchanges across every Γ did (lag: > 0)
  double interface_dissipated_j = 0;  ///< taken out by the interface controllers (≥ 0)
  /**
   * What the observers hold now, the inner sides' work they have not yet seen included: the
   * controllers' backlog. EnergyAboveBound ≤ this (equal but for credit the floors forgot).
   */
  double pending_excess_j = 0;
  /** The backlog the primary leaves to the shells now (kPrimaryReserve of its energy). */
  double primary_reserve_j = 0;
  /** Work the port limits kept out of the regions (PortWorkLimits), J (≥ 0). */
  double port_refused_j = 0;
  /**
   * What the port limits guarantee, whatever the timing: EnergyAboveBound ≤ this. Over the
   * links, the largest allowance each side has used, kCreditMemory of the outer region's largest
   * energy and the largest load work taken in lock-step (docs/regions.md, "The port limits").
   * (The observers themselves, pending_excess_j, can pass it on real threads by a floor raise
   * made on a stale view, which EnergyAboveBound does not count.) 0 with the limits off
   * (kDampingOnly, kOff): nothing is guaranteed then.
   */
  double backlog_bound_j = 0;
};

/**
 * The object solved as asynchronous regions (see RegionPartition): the primary at the primary
 * rate 1/solver.dt, the first secondary shell at adaptivity.secondary_rate, further shells at
 * adaptivity.outer_rate, each with the substeps its own stability limit requires. Neighbouring
 * regions a (inner) and a + 1 (outer, which owns their interface Γ) are linked through two
 * BoundaryChannels:
 *
 *   outer → inner: Γ displacements at the outer region's step times. The inner region takes Γ at
 *                  each of its substep times on the line between the newest two (interpolation:
 *                  the schedule keeps the outer region ahead; a late one is held, never
 *                  extrapolated).
 *   inner → outer: with adaptivity.coupling = "displacement", the inner region's displacements
 *                  on its band of elements next to Γ; the outer region evaluates the inner
 *                  region's force on Γ itself from them (extrapolated linearly to its own time)
 *                  and its own current Γ, so only the cross-coupling lags. With "force", the
 *                  inner region's forces on Γ, extrapolated (at one rate, as "displacement").
 *
 * At equal rates the scheme is exactly monolithic central difference (k = 1 reproduces the
 * reference to round-off). With unequal rates the lagged coupling acts as negative damping; whether
 * it is stable depends on the configuration, so the coupled spectral radius is computed before a
 * configuration may run (docs/regions.md).
 *
 * StepPrimary() and StepRegion() are the only code that advances the simulation. The virtual-time
 * schedule (RunTrial, EstimateCoupledStability) calls them in a deterministic order; the
 * real-time schedule calls them from one thread per region.
 *
 * Threads: each region's step from one thread; steps never allocate, lock or throw. Everything
 * else: one thread, while no steps run.
 */
class AsyncRegions {
 public:
  /** Divergence: energy above this factor × (initial energy + input work), as in the reference. */
  static constexpr double kEnergyGrowthFactor = 1e4;
  /** Substeps keep each region's step at most this fraction of its own critical step. */
  static constexpr double kSubstepSafety = 0.95;

  /** Share of its outer region's material damping an interface may spend on the energy its
   *  exchange creates before its controller dissipates (ObserveInwardLink). */
  static constexpr double kDampingCredit = 0.5;
  /** The most credit an interface keeps, as a share of its outer region's energy. */
  static constexpr double kCreditMemory = 0.1;
  /** The backlog the primary's controller leaves to the shells, as a share of its own energy:
   *  beyond it, the primary damps too (its last resort; OutwardLinkExcess). */
  static constexpr double kPrimaryReserve = 0.1;
  /** Each link's port allowance, as a share of its two regions' energies: a side's port does
   *  work only while the link's observer, as that side knows it, stays below it
   *  (InwardPortLimit, OutwardPortLimit). */
  static constexpr double kPortAllowance = 0.02;
  /** The strain at which the whole object's energy is the port allowance's floor (PortFloorJ). */
  static constexpr double kPortFloorStrain = 1e-4;
  /** The port allowance's floor: the object's energy at a uniform strain of kPortFloorStrain, J. */
  static double PortFloorJ(const Material& material, double mass_kg);
  double port_floor_j() const { return port_floor_j_; }

  /**
   * kPassive: every interface's controller takes out what its exchange creates, and — with the
   * force exchange, or at another rate (PortLimited) — its port limits bound what the controllers
   * cannot take out in time (always, in the daemon and the sweep). For analysis only — what each
   * part costs and holds (docs/regions.md); no configuration file can ask for them: kDampingOnly,
   * the controllers without the port limits; kOff, the bare exchange and the lag's own instability.
   */
  enum class InterfaceControl { kPassive, kDampingOnly, kOff };

  /** What an inner region sends the outer one for Γ. */
  enum class Coupling { kForce, kDisplacement };

  /**
   * control: whether the interface controllers act (InterfaceControl).
   * substep_safety: each region takes the fewest substeps that keep its step at most this
   * fraction of its own critical step. Above 1 a region may run past its limit: only the stability
   * stress test asks for that, to watch divergence being detected.
   * @throws Error for invalid adaptivity settings or a substep_safety that is not positive.
   */
  explicit AsyncRegions(const Scene& scene, double substep_safety = kSubstepSafety,
                        InterfaceControl control = InterfaceControl::kPassive);
  ~AsyncRegions();

  const RegionPartition& partition() const { return partition_; }
  int num_regions() const { return partition_.num_regions(); }
  const RegionSchedule& schedule(RegionIndex region) const;

  /** Integer ticks of the virtual-time clock: 1 tick = 1 / ticks_per_second() s. */
  std::int64_t ticks_per_second() const { return ticks_per_second_; }
  /** One step of the region (its nominal period / its substeps), ticks. */
  std::int64_t period_ticks(RegionIndex region) const;
  std::int64_t common_period_ticks() const { return common_period_ticks_; }
  /** Time of a region's current state, ticks. Read by the thread stepping that region. */
  std::int64_t state_ticks(RegionIndex region) const;

  /** Zero state at t = 0 with the initial snapshots published. */
  void Reset();
  /** A reproducible random state (free DOFs), consistent on every Γ, at t = 0. */
  void SetRandomState(unsigned seed);

  /**
   * The object's present motion on the fine lattice (ObjectState): at each lattice point the
   * value of the region that owns it — an independent node's own, or between a coarse cell's
   * vertices the cell's trilinear field (which is what a hanging node is held to) — velocities
   * (u − u⁻)/h with each region's own substep. The regions are taken as they are: on the
   * real-time schedule the secondaries may be a step or two ahead of the primary.
   * One thread, while no steps run.
   */
  ObjectState CaptureState() const;
  /**
   * Starts the regions at t = 0 from `state` instead of rest (a configuration switched while the
   * object is deformed): every independent node takes its lattice point's displacement, each
   * region its u⁻ = u − v·h for its own substep h, the contact stays where the state has it
   * (primary_contact_m), the boundaries are published and the energy balance starts afresh.
   * One thread, while no steps run.
   * @throws Error for a state of another lattice.
   */
  void RestoreState(const ObjectState& state);

  /**
   * The object's surface, for drawing it while the regions run (hapticsimd's deformation_t):
   * the lattice points on the object's surface (touched by occupied and empty or outside cells:
   * the cube's faces) as ids (ix · ny + iy) · nz + iz, ascending, in the order ReadSurface gives
   * their displacements.
   */
  const std::vector<std::int32_t>& surface_ids() const { return surface_.ids; }
  /**
   * Any thread, while the steps run: asks every region to publish its part of the surface after
   * its next step, and returns the request's number for SurfaceServed. The steps stay real-time:
   * each loads one atomic, and copies its part of the surface (no allocation) when asked.
   */
  std::uint64_t RequestSurface() noexcept;
  /** Any thread: whether every region has published its part since request `request` was made
   *  (a region that does not step — parked, or skipping a stall — publishes nothing). */
  bool SurfaceServed(std::uint64_t request) const noexcept;
  /** Times region `region` has published its part of the surface (Reset, RestoreState and the
   *  steps asked to). Any thread. */
  std::uint64_t surface_publications(RegionIndex region) const noexcept;
  /**
   * Any thread: the surface's displacements as the regions last published them, 3 per surface
   * point in surface_ids' order, m. Each point has the value of the region that owns it, as
   * CaptureState takes it (a hanging point its coarse cell's field); on real threads each region's
   * part is as of its own last publication. Reset and RestoreState publish every part. False when
   * a region's publication raced every attempt to read it. Allocates: not for a real-time thread.
   */
  bool ReadSurface(std::vector<double>* displacement_m) const;

  /**
   * Primary thread: one primary step (a period, or one of its substeps). contact_next is the
   * contact displacement at the end of the step (m, object frame). Returns the reaction R at the
   * contact at the step's start time, N (the force on the user is −R).
   */
  std::array<double, 3> StepPrimary(const std::array<double, 3>& contact_next) noexcept;
  /**
   * Primary thread, when the tool touches through a stroke's proxy (RegionPartition::
   * proxy_contact; StepPrimary does not drive the contact then): one primary step whose loads on
   * proxy_loaded_dofs(), in that order, `push` gives from the step's end (ProxyPush).
   */
  void StepPrimaryPushed(EndOfStepLoad& push) noexcept;
  /** The primary's DOFs a stroke's proxy may push (ProxyContact::loaded_dofs on
   *  RegionPartition::PrimaryProxySurface); empty for a driven contact. */
  const std::vector<int>& proxy_loaded_dofs() const { return proxy_loaded_dofs_; }
  /** The primary's state vector (its owned DOFs current), in the mesh's DOF order: what a proxy
   *  reads the surface from. Primary thread. */
  const Eigen::VectorXd& primary_state() const noexcept;
  /**
   * Where the contact is in the primary's current state (the last step's contact_next; zero
   * after Reset), m: where a period's substeps start from. Primary thread.
   */
  std::array<double, 3> primary_contact_m() const noexcept;
  /** A secondary region's thread: one step of region `region` ≥ 1. */
  void StepRegion(RegionIndex region) noexcept;
  /**
   * A secondary region's thread, after a stall: moves the region's clock on by `steps` steps
   * without stepping (its state is held, as its neighbours held its boundary meanwhile) and
   * publishes its boundary at the new time. Stepping the missed steps late instead would couple it
   * to its neighbours' present state with the stall's delay — a lag the stability estimate did
   * not assume, and one that diverges (docs/reliability.md).
   */
  void SkipRegion(RegionIndex region, std::int64_t steps) noexcept;
  /** A secondary region woken more of its periods late than this skips them (SkipRegion)
   *  instead of stepping them: the daemon's threads and RealTimeSchedule alike. */
  static constexpr int kSkipAfterLatePeriods = 3;
  /** How far the primary's newest boundary from region 1 was behind the primary's step time at
   *  its last step, s (0 with no secondary region). Any thread (relaxed atomic). */
  double primary_boundary_age_s() const noexcept {
    return primary_boundary_age_s_.load(std::memory_order_relaxed);
  }
  /** Region `inner`'s steps whose outer Γ the outer region had not published up to their end
   *  (held: its thread was late for them), since construction. Any thread (relaxed atomic). */
  std::int64_t held_boundary_steps(RegionIndex inner) const noexcept;
  /**
   * Virtual time: steps the secondary regions (outermost first, recursively) until region 1 can
   * supply Γ at `ticks`, as the primary's next step needs.
   */
  void AdvanceSecondariesTo(std::int64_t ticks) noexcept;
  /** Virtual time, before each primary step: the secondaries stepped in the stepping order —
   *  AdvanceSecondariesTo its end, or at a period's start every secondary wake released by then. */
  void AdvanceSecondariesForPrimaryStep() noexcept;
  /** How virtual-time runs step the regions (SteppingOrder; kSubsteps unless set). One thread,
   *  while no steps run. */
  void SetSteppingOrder(SteppingOrder order);
  SteppingOrder stepping_order() const noexcept { return stepping_order_; }

  /**
   * True when the region's state is within `tolerance_m` of rest (every owned displacement, now
   * and one step ago): with no load, stepping it on would change nothing a user could feel. The
   * thread stepping that region (or any thread while no steps run).
   */
  bool RegionAtRest(RegionIndex region, double tolerance_m) const noexcept;

  /**
   * Switches the interface controllers on or off, and starts the energy balance afresh (off,
   * the observers drift with nothing to hold them). One thread, while no steps run.
   */
  void SetInterfaceControl(InterfaceControl control) {
    control_ = control;
    ResetEnergyAccount();
  }

  /** The energy balance since Reset. One thread, while no steps run. */
  EnergyAccount Energies() noexcept;
  /** Its input_work_j alone, without the stored energy's K·u. */
  double InputWorkJ() const noexcept;

  /** The balance as the running threads see it (PublishedBalance). */
  struct PublishedBalanceView {
    double backlog_j = 0;  ///< what the interface observers hold, their positive parts summed
    double stored_j = 0;   ///< Σ of the regions' discrete energies at their last steps
    /** What the primary leaves to the shells by design (kPrimaryReserve of its energy): the
     *  backlog above it is what EnergyAboveBound counts. */
    double primary_reserve_j = 0;
    /** Σ of the regions' StateEnergy at their last steps: what the state holds, J. */
    double state_energy_j = 0;
    /**
     * What the energy balance lets the object hold now, J: the state energy at the balance's
     * start + the contact's work − the damping (the secondaries' less the kDampingCredit the
     * interfaces may spend) + the primary's reserve. Not the backlog: that is what the
     * controllers have yet to take out, and a backlog that outgrows everything the contact put
     * in is the controllers losing (Runaway).
     */
    double allowed_j = 0;
  };
  /**
   * What the interface observers hold (EnergyAccount::pending_excess_j, each link's positive
   * part) and the stored energy, from the values each region published at its last step: any
   * thread, while the steps run (the daemon watches the coupling's energy balance with it). Each
   * term is one region's view as of its own last step, so on real threads the sum mixes times up
   * to the lag between the regions. With the controllers off (kOff) the energies are not published.
   */
  PublishedBalanceView PublishedBalance() const noexcept;

  /**
   * The runaway watch: the state holds more than kRunawayFactor × what the energy balance allows
   * (and more than that factor × the port floor, so that rest is not measured in round-off). The
   * interface controllers and the port limits hold the regions' *discrete* energies to the
   * balance; this is the one thing they cannot see — a region whose discrete energy is no longer
   * a norm of its state (one element deep between the contact and a Γ whose motion aliases a
   * faster neighbour's; docs/regions.md, "The runaway watch"). The daemon then moves the regions
   * to equal rates, which are monolithic central difference and stable by each region's own limit.
   * Any thread (reads what PublishedBalance reads).
   */
  bool Runaway(const PublishedBalanceView& view) const noexcept {
    return view.state_energy_j > kRunawayFactor * std::max(view.allowed_j, port_floor_j_);
  }
  /**
   * The watch as the trials and the daemon run it, once per primary period: true once Runaway
   * has held for kRunawayPeriods periods in a row where it applies (watches_runaway).
   * `periods_in_a_row` is the caller's count, kept between calls (0 for new regions).
   */
  bool RunawayHeld(const PublishedBalanceView& view, int* periods_in_a_row) const noexcept {
    *periods_in_a_row = watches_runaway() && Runaway(view) ? *periods_in_a_row + 1 : 0;
    return *periods_in_a_row >= kRunawayPeriods;
  }
  /**
   * Above what a stable region's state can hold against its discrete energy: for a mode of
   * frequency ω stepped at h, ½(m v² + k u²) ≤ (discrete energy) / (1 − hω/2), and substeps keep
   * hω/2 ≤ kSubstepSafety, so a factor of 1 / (1 − 0.95) = 20 at the most, in a state that is
   * all the stiffest mode. Measured: 0.90–0.93 on the paper's 48 configurations under the 1 cm
   * press, up to 2.3 from a random state.
   */
  static constexpr double kRunawayFactor = 32;
  /**
   * Primary periods in a row that Runaway must hold before it counts. The state energy holds a
   * prescribed jump of the contact node (a restart keeping the contact, a tip caught up with) at
   * once, the balance credits its work a step later (its Δ is centred): measured in the daemon's
   * soak on the default scene, 0.016–0.021 J against 0 to 4·10⁻⁴ J allowed, in one period at equal
   * rates. A runaway grows for tens of periods (stress case 160: above the factor from period 17,
   * diverged at 56).
   */
  static constexpr int kRunawayPeriods = 5;
  /**
   * Whether Runaway applies to these regions: the interface controllers on (kPassive), more than
   * one region, and the production margin (each step within kSubstepSafety of its own limit; the
   * stress test's near-limit cases step closer, where the factor above no longer bounds a stable
   * state).
   */
  bool watches_runaway() const noexcept {
    return control_ == InterfaceControl::kPassive && num_regions() > 1 &&
           substep_safety_ <= kSubstepSafety;
  }

  /** Positive-definite energy of the coupled state (all regions), J. */
  double Energy() noexcept;
  /** Its kinetic part, ½ Σ m v² over the owned DOFs (no K·u needed), J. */
  double KineticEnergy() const noexcept;

  /** A trial of the scene's input on the virtual-time schedule. */
  TrialResult RunTrial();
  /** A trial of another input on the same regions (the sweep reuses one set per configuration). */
  TrialResult RunTrial(const InputSettings& input);
  /** The scene's own input, from rest, with frames of the whole object (CaptureState) as asked:
   *  what `hapticsim simulate --vtk` writes. */
  TrialResult RunTrial(const TrialFrames& frames);
  /**
   * The same trial from SetRandomState(seed) instead of rest, so every mode starts excited (the
   * stability stress test: an unstable mode cannot hide behind a smooth input).
   */
  TrialResult RunTrialFromRandomState(const InputSettings& input, unsigned seed);

  /** The region whose state is largest (or non-finite): where a divergence grew. */
  RegionIndex LargestStateRegion() const;

  /**
   * Spectral radius of the one-common-period map by power iteration from a random state: after
   * `burn_in_periods`, the growth per period averaged over windows of `window_periods`, window
   * after window while it still rises (by more than kStillRising of its distance from neutral,
   * up to `max_windows`); the radius is the largest window's. One window (max_windows = 1) is a
   * plain fixed-length iteration. `seed`: the random start state.
   * @throws Error when window_periods < 1, burn_in_periods < window_periods or max_windows < 1.
   */
  CoupledStability EstimateCoupledStability(int burn_in_periods = 600, int window_periods = 300,
                                            int max_windows = 8, unsigned seed = 7);
  /** A window growing faster than the one before by this fraction of |log growth| is rising. */
  static constexpr double kStillRising = 0.1;

  /**
   * Free decay from a random state (no input): the coupled energy at the start and after every
   * `periods_per_checkpoint` common periods, `checkpoints` times, J.
   */
  std::vector<double> FreeDecayEnergies(int periods_per_checkpoint, int checkpoints,
                                        unsigned seed = 11);
  /** Compute time spent in a region's steps since Reset, s. */
  double compute_seconds(RegionIndex region) const;

 private:
  struct Region;
  double SetUpProxy(const ContactSettings& contact);
  void BuildIntegrator(RegionIndex region, Region& state);
  void PublishInitialSnapshots();
  /** Reset; each region's state set to `u` and velocities `v` (u⁻ = u − v·h), Γ published. */
  void StartFrom(const Eigen::VectorXd& u, const Eigen::VectorXd& v);
  TrialResult RunTrialFromCurrentState(const InputSettings& input, const TrialFrames& frames = {});
  void PublishInward(RegionIndex region) noexcept;
  void PublishOutward(RegionIndex region) noexcept;
  /** After a step: the boundaries for the neighbours, and the surface if a reader asked. */
  void PublishStep(RegionIndex region) noexcept;
  void PublishSurface(Region& region) noexcept;
  void BuildSurface();
  void StepRegionAt(RegionIndex region, const std::array<double, 3>* contact_next,
                    std::array<double, 3>* reaction, EndOfStepLoad* push = nullptr) noexcept;
  void ReadInnerLoads(RegionIndex region, double t0) noexcept;
  bool AtOneRate(RegionIndex inner) const noexcept;     // the link outwards of `inner`: see .cpp
  size_t BandOffset(RegionIndex inner) const noexcept;  // … its outward snapshot: see .cpp
  void ControlInterfaces(RegionIndex region, double* asked_inward, double* asked_outward,
                         PortWorkLimits* limits) noexcept;
  double ObserveInwardLink(RegionIndex region, double energy) noexcept;
  double InwardPortLimit(RegionIndex region, double energy, bool lockstep) noexcept;
  bool InLockStep(RegionIndex region) const noexcept;
  bool PortLimited(RegionIndex inner) const noexcept;  // the link outwards of `inner`: see .cpp
  double OutwardPortLimit(RegionIndex region, double energy) noexcept;
  double OutwardLinkExcess(RegionIndex region) const noexcept;
  static double PrimaryReserve(RegionIntegrator& primary) noexcept;
  void AccountStep(RegionIndex region, double asked_inward, double asked_outward) noexcept;
  void PublishEnergyAccount(Region& region) noexcept;
  void ResetEnergyAccount() noexcept;
  void AdvanceRegionTo(RegionIndex region, std::int64_t ticks) noexcept;
  void ReleaseSecondariesBy(std::int64_t ticks) noexcept;  // the threads' order: see its .cpp
  void AdvancePrimaryTo(std::int64_t ticks) noexcept;
  void ScaleAll(double factor);
  double StateNorm() const;
  /**
   * √ of the energy central difference conserves along a mode, ½ Σ m v² + ½ u_{n−1}ᵀ K u_n, summed
   * over the regions: unlike the Euclidean norm of (u_n, u_{n−1}), it does not swing with an
   * oscillating mode's phase, so growth measured in it is the modulus alone.
   */
  double OrbitNorm() noexcept;
  /** EstimateCoupledStability in one norm; nullopt when the orbit norm is not positive. */
  std::optional<CoupledStability> PowerIterate(int burn_in_periods, int window_periods,
                                               int max_windows, bool orbit_norm, unsigned seed);

  RegionPartition partition_;
  bool primary_one_element_deep_ = false;  // see PortLimited
  Coupling coupling_;
  InterfaceControl control_;
  std::vector<std::unique_ptr<Region>> regions_;
  std::int64_t ticks_per_second_ = 0, common_period_ticks_ = 0;
  std::atomic<double> primary_boundary_age_s_{0};
  double port_floor_j_ = 0;
  double state_energy_at_reset_j_ = 0;  // Σ StateEnergy when the energy balance last started
  double substep_safety_ = kSubstepSafety;
  SteppingOrder stepping_order_ = SteppingOrder::kSubsteps;
  std::vector<std::int64_t> release_lead_ticks_;  // per region, in the threads' order

  // The surface (core/regions/region_surface.cpp): each of its values (3 per point) is a sum of terms
  // [term_start[v], term_start[v + 1]), each a weight times a region's published surface value.
  struct SurfaceTerm {
    RegionIndex region;
    int slot;  // into that region's surface_dofs
    double weight;
  };
  struct SurfaceMap {
    std::vector<std::int32_t> ids;
    std::vector<int> term_start;
    std::vector<SurfaceTerm> terms;
  } surface_;
  std::atomic<std::uint64_t> surface_request_{0};

  // A stroke's proxy (RegionPartition::proxy_contact): the primary's loaded DOFs, the spring,
  // and for the stability estimate, the contact node's slot among them.
  std::vector<int> proxy_loaded_dofs_;
  double proxy_stiffness_n_per_m_ = 0;
  int proxy_contact_slot_ = 0;
};

/**
 * How far the stored energy is above what the interface controllers guarantee,
 * stored at start + input work − damping + kDampingCredit × credited damping + the primary's
 * reserve, J: ≤ 0 (to the observer's one-step lag) while the controllers keep up.
 */
inline double EnergyAboveBound(const EnergyAccount& e, double stored_at_start) {
  return e.stored_j - stored_at_start - e.input_work_j + e.damping_dissipated_j -
         AsyncRegions::kDampingCredit * e.credited_damping_j - e.primary_reserve_j;
}

}  // namespace hapticsim
