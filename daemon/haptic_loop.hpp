#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "core/regions/async_regions.hpp"
#include "core/regions/stability_stress.hpp"
#include "daemon/contact_tracker.hpp"
#include "daemon/input_handoff.hpp"
#include "daemon/input_resampler.hpp"
#include "daemon/loop_counters.hpp"
#include "daemon/port_guard.hpp"
#include "daemon/region_handover.hpp"
#include "daemon/secondary_parking.hpp"
#include "daemon/sliding_contact.hpp"
#include "rt/deadline_monitor.hpp"
#include "rt/spsc_ring.hpp"

namespace hapticsim {

/** One primary period's answer, as the primary thread hands it to the I/O thread. */
struct ForceRecord {
  std::int64_t period = -1;  ///< the primary period, counting every one since the start
  std::int64_t seq = -1;     ///< the newest input it answers
  /// The oldest input it answers: every seq from first_seq to seq reached the primary since the
  /// last answer and was used (the tip is resampled from all of them); first_seq = seq when one
  /// did, or none (the same seq answered again).
  std::int64_t first_seq = -1;
  std::int64_t utime_us = 0;        ///< CLOCK_MONOTONIC, µs
  std::array<double, 3> force_n{};  ///< on the user
  double error_percent = -1;
  std::int32_t flags = 0;  ///< force_feedback_t::FLAG_* bits
};

/** One primary period as the black box keeps it (the last cycles are logged on a fault). */
struct BlackBoxRecord {
  std::int64_t time_ns = 0;  ///< the period's wake-up, CLOCK_MONOTONIC
  std::int64_t seq = -1;
  std::array<double, 3> position_m{};
  std::array<double, 3> force_n{};      ///< as sent (zero out of contact or after a fault)
  std::array<double, 3> raw_force_n{};  ///< as simulated
  double port_energy_j = 0;             ///< the port guard's observed energy (PortGuard)
  double error_percent = -1;
  std::int32_t flags = 0;
};

/** Flags of force_feedback_t (kept equal to the LCM constants; a test checks). */
namespace force_flags {
inline constexpr std::int32_t kInContact = 1;
inline constexpr std::int32_t kErrorTargetExceeded = 2;
inline constexpr std::int32_t kLookupClamped = 4;
inline constexpr std::int32_t kInputStale = 8;
inline constexpr std::int32_t kReconfiguring = 16;
inline constexpr std::int32_t kNoErrorMap = 32;
inline constexpr std::int32_t kInputRejected = 64;
inline constexpr std::int32_t kBoundaryStale = 128;
inline constexpr std::int32_t kForceLimited = 256;
inline constexpr std::int32_t kPortDissipating = 512;
inline constexpr std::int32_t kFaultLatched = 1024;
}  // namespace force_flags

/**
 * The real-time part of hapticsimd: the asynchronous regions on one thread each. The primary
 * thread runs at the primary rate on absolute CLOCK_MONOTONIC releases; every period it takes the
 * newest device input (a seqlock slot), prescribes the contact, steps, and hands the force to the
 * I/O thread (a lock-free ring). Secondary threads step at their own rates, released ahead as in
 * RealTimeSchedule. None of them allocates, locks, logs or does I/O; deadline misses go to
 * lock-free DeadlineMonitors that the supervisor drains.
 *
 * Contact (ContactTracker): the tool tip touching the surface picks the nearest surface node.
 * When the regions are centred on it the node follows the tip at once; otherwise the loop renders
 * zero force, flagged "reconfiguring", and publishes the node it wants (wanted_contact_node) for
 * the supervisor, which centres the regions on it (Reconfigure, Handover::kRampIn); the contact
 * then engages with its force ramped in from zero. Out of contact the force is zero. After a
 * restart from rest (Start, a reset, a fault) a tip already inside the object renders nothing
 * until it has left the object once.
 *
 * Sleeping at rest: out of contact, once every region is within kRestTolerance_m of rest, the
 * secondary threads park (blocked, no CPU), the regions are set exactly to rest and the primary
 * stops stepping them; it still answers every input and tracks the tip, and the period the tip
 * engages it wakes them and steps on from rest in that same period (the secondaries restart on
 * its release grid). Asleep with no fresh input, the primary thread itself blocks until an input
 * arrives (OfferInput wakes it) and rejoins its release grid. See docs/operations.md.
 *
 * Reconfiguration is gapless: the primary thread never stops. It pauses the regions (answers
 * every period, flagged "reconfiguring": with zero force, or — carrying the motion to a new
 * configuration on the same node — with the force a contact engaged until then had) while the
 * supervisor joins the old secondary threads, installs the new regions and starts their threads,
 * and resumes them on its own release grid, so every input still gets its answer.
 */
class HapticLoop {
 public:
  struct Options {
    double stale_after_s = 0.05;
    bool zero_force_when_stale = true;
    PortGuardSettings port;      ///< the device profile the force sent obeys
    int fifo_priority = 0;       ///< SCHED_FIFO for the region threads (0: normal scheduling)
    std::vector<int> cpus;       ///< pin the region threads here (empty: no pinning)
    double engage_ramp_s = 0.1;  ///< a contact that engages late ramps its force in over this
    bool sleep_at_rest = true;   ///< regions at rest and untouched stop stepping until a touch
    /** The port guard off (PortGuard::Mode::kOffForTests): hapticsimd --no-port-guard, soaks and
     *  tests in a sandbox only. */
    bool port_guard_off = false;
  };
  using ForceRing = SpscRing<ForceRecord, 4096>;
  using BlackBoxRing = SpscRing<BlackBoxRecord, 4096>;

  /** @throws Error for an invalid scene. */
  HapticLoop(const Scene& scene, const Options& options);
  ~HapticLoop();

  /** Starts the region threads. Returns what the system refused of the RT settings ("" = all). */
  std::string Start();
  /** Stops and joins the region threads. */
  void Stop();
  /** What a touching tool feels when new regions take over (Reconfigure). */
  enum class Handover {
    /** The regions start from rest; a tool inside must lift off before it feels force again
     *  (a reset, a fault's restart). */
    kFromRest,
    /** From rest around a new centre: a tool inside engages again, its force ramped in from
     *  zero (the regions moved onto the node it touches). */
    kRampIn,
    /** Around the same centre, from the old regions' motion (AsyncRegions::CaptureState and
     *  RestoreState): a tool inside feels the force it felt, held for the periods the regions
     *  are being installed, and the contact node catches up with the tip from where it was held
     *  (ContactTracker::CatchUpFrom). A configuration switched in contact. With a sliding tool
     *  also around another node: the regions following its proxy, which goes on where it was. */
    kCarryMotion,
  };
  /**
   * Replaces the regions by those of `scene` (another adaptive configuration of the same object,
   * or the same one centred on another contact node). The regions are built while the loop runs;
   * the primary thread then pauses them for a few periods (every input answered, flagged
   * "reconfiguring": with zero force, or with kCarryMotion the held force) and resumes on the new
   * ones, as `handover` says. Supervisor thread only.
   * @throws Error for an invalid scene, another primary rate, kCarryMotion around another contact
   *         node, or a primary thread that does not answer within a second (the running loop is
   *         left as it was).
   */
  void Reconfigure(const Scene& scene, Handover handover = Handover::kFromRest);
  /** How long the last Reconfigure took, and where (s): building the new regions, waiting for the
   *  primary to pause, joining the old secondary threads; all of it. Supervisor thread only. */
  struct ReplacementTimes {
    double build_s = 0, pause_s = 0, join_s = 0, total_s = 0;
  };
  const ReplacementTimes& last_replacement() const { return last_replacement_; }
  /** The object's deformed surface as the running regions published it (TakeSurface). */
  struct SurfaceFrame {
    /** Regions installed since the loop was made when it was taken: changes with every
     *  Reconfigure (another configuration, a move, a restart). */
    std::int64_t configuration_id = -1;
    AdaptivitySettings configuration;    ///< the regions' (primary_size, secondary_lod, rates)
    LatticeIndex centre{};               ///< the node the regions are centred on
    bool in_contact = false;             ///< the newest period, or one of the last 5, engaged
    /// The surface nodes on the wire's lattice (ContactObject::ToWireIds of
    /// AsyncRegions::surface_ids, the same for every configuration): id = (ix · n + iy) · n + iz, n
    /// = nodes_per_axis.
    std::vector<std::int32_t> ids;
    std::int32_t nodes_per_axis = 0;     ///< ContactObject::wire_nodes_per_axis
    double spacing_m = 0;                ///< the lattice's, m
    std::vector<double> displacement_m;  ///< 3 per id, m
    std::int64_t asked_ns = 0;           ///< CLOCK_MONOTONIC when the regions were asked
    bool complete = true;  ///< every region published after being asked (else its last part)
  };
  /**
   * The deformation thread (any thread but the region threads): asks the running regions for the
   * surface and waits until every region has published its part after its next step, at most
   * `max_wait_ns` (a parked or stalled region keeps its last part; regions asleep are at rest
   * and are read at once), then reads it into `frame`. The region threads only copy their part
   * when asked (AsyncRegions::RequestSurface); the lock taken here is the supervisor's and this
   * thread's alone. False when the regions were replaced meanwhile (ask again).
   */
  bool TakeSurface(std::int64_t max_wait_ns, SurfaceFrame* frame);
  /** The node the tool wants the regions centred on (see ContactTracker::wanted_node). */
  std::optional<LatticeIndex> wanted_contact_node() const;
  /** True while the tip is inside on a node the regions are not centred on (force zero). */
  bool contact_waiting() const { return counters_.contact_waiting.value(); }
  /** True while a sliding tool's regions should follow its proxy onto wanted_contact_node(), the
   *  object's motion carried (Handover::kCarryMotion onto another node). */
  bool contact_following() const { return counters_.contact_following.value(); }
  /** Whether the tool touches through a sliding proxy (contact.model = "proxy", SlidingContact). */
  bool sliding_contact() const { return sliding_.has_value(); }
  /** The object as the tool meets it (its voxels and drivable nodes): fixed for the loop's life. */
  const ContactObject& contact_object() const { return object_; }
  /** The node the regions are centred on. Supervisor thread only. */
  const LatticeIndex& centre_node() const { return centre_; }
  /** Regions replaced since the loop was made (Reconfigure calls that took effect). */
  std::int64_t reconfigurations() const { return reconfigurations_; }
  /** Primary periods answered while the regions were paused for a reconfiguration. */
  std::int64_t paused_periods() const { return counters_.paused_periods.value(); }
  /** CLOCK_MONOTONIC of the last primary period in contact, ns (0: never). */
  std::int64_t last_contact_ns() const { return counters_.last_contact_ns.value(); }
  bool running() const { return running_.load(); }

  /**
   * I/O thread: hands an accepted input to the primary (and wakes it if it waits). Every input
   * offered reaches the primary in order (a ring; when the ring is full, the newest still does),
   * and the period's answer names every input it took (ForceRecord::first_seq … seq).
   */
  void OfferInput(const DeviceSample& sample) noexcept;
  /** True while the regions sleep at rest (not stepped; the secondary threads parked). */
  bool asleep() const { return counters_.asleep.value(); }
  /**
   * True while asleep with no fresh input: the primary thread waits for an input instead of
   * running periods, and the I/O thread may wait longer between polls.
   */
  bool idle() const { return counters_.idle.value(); }
  /** Times the regions went to sleep since the loop was made. */
  std::int64_t sleeps() const { return counters_.sleeps.value(); }
  /**
   * CLOCK_MONOTONIC of the primary thread's last sign of life, ns: a period done, or a wait for
   * input that came round (at least every kIdleWait_s). 0 before the first period.
   */
  std::int64_t primary_alive_ns() const;
  /** I/O thread: the forces, one per primary period. */
  ForceRing& forces() { return forces_; }
  /** Supervisor: every primary period's record, for the black box. */
  BlackBoxRing& black_box() { return black_box_; }
  /** Supervisor: the error and flags every force carries from now on. */
  void SetErrorState(double error_percent, std::int32_t flags) noexcept;
  /** Supervisor: per region. */
  DeadlineMonitor& monitor(RegionIndex region) { return *monitors_[region]; }
  const AsyncRegions& regions() const { return *regions_; }
  /** Primary periods run on stale input. */
  std::int64_t stale_periods() const { return counters_.stale_periods.value(); }
  /**
   * Faults the port guard latched (non-finite or diverging force, a stalled primary), and the
   * re-arms since: a latched fault holds the force at zero until the regions have restarted from
   * rest (the supervisor's RestartFromRest) and the tool is out of the object.
   */
  std::int64_t force_faults() const { return counters_.force_faults.value(); }
  std::int64_t rearms() const { return counters_.rearms.value(); }
  bool fault_latched() const { return counters_.fault_latched.value(); }
  /** The kind of the newest latched fault (PortGuard::Fault). */
  PortGuard::Fault last_fault() const {
    return static_cast<PortGuard::Fault>(counters_.last_fault.value());
  }
  /** Periods whose force the guard limited (envelope, ramp, slew) or dissipated energy from. */
  std::int64_t limited_periods() const { return counters_.limited_periods.value(); }
  std::int64_t dissipating_periods() const { return counters_.dissipating_periods.value(); }
  const PortGuardSettings& port_settings() const { return options_.port; }
  bool port_guard_off() const { return options_.port_guard_off; }
  /** Energy the port guard's passivity controller has dissipated, J. */
  double port_energy_dissipated_j() const { return counters_.port_dissipated_j.value(); }
  /**
   * The coupling's own energy balance, watched every primary period (AsyncRegions::
   * PublishedBalance): what the interface observers hold now and the most since the loop was
   * made, J, and the periods in which that backlog, less the reserve the primary leaves to the
   * shells by design, exceeded kBacklogTolerance of the regions' largest energy since they last
   * started from rest (at least their port floor): energy the exchanges created faster than the
   * controllers took it out. Any thread.
   */
  double interface_backlog_j() const { return counters_.interface_backlog_j.value(); }
  double interface_backlog_max_j() const { return counters_.interface_backlog_max_j.value(); }
  std::int64_t energy_balance_violations() const { return counters_.balance_violations.value(); }
  /**
   * Sets of regions whose state outgrew what the energy balance allows (AsyncRegions::Runaway,
   * watched every primary period; counted once per set of regions): the supervisor moves the
   * regions off that configuration to equal rates. Any thread.
   */
  std::int64_t runaways() const { return counters_.runaways(); }
  /** The last runaway's state energy and what the balance allowed then, J (read after runaways()
   *  rose: stored before its count is released). */
  RunawayEnergies last_runaway() const { return counters_.last_runaway(); }
  /** The stress test's tolerance for a controlled exchange (StressOutcome::kGrowingBacklog). */
  static constexpr double kBacklogTolerance = StressOutcome::kGrowingBacklog;
  /**
   * A secondary region's stalls (woke more than kSkipAfterLatePeriods of its periods late) and the
   * periods it skipped holding its state, since the loop was made. Any thread.
   */
  std::int64_t stalls(RegionIndex region) const { return counters_.stalls[region].value(); }
  std::int64_t skipped_periods(RegionIndex region) const {
    return counters_.skipped_periods[region].value();
  }
  /** A secondary region woken more periods late than this skips them instead of stepping them. */
  static constexpr int kSkipAfterLatePeriods = AsyncRegions::kSkipAfterLatePeriods;
  /**
   * The primary's boundary from region 1 older than this means the secondary thread is not
   * running: every answer is flagged kBoundaryStale (the supervisor logs it too).
   */
  static constexpr double kStaleBoundary_s = 0.1;
  /** Regions a loop keeps counters for (a scene has at most 1 + 8). */
  static constexpr int kMaxRegions = 16;
  /**
   * A region whose every owned displacement (now and a step ago) is within this of rest counts
   * as at rest, m. Zeroing 0.1 µm changes the force by ~10⁻⁵ N on the paper's cube: far below
   * any device's resolution.
   */
  static constexpr double kRestTolerance_m = 1e-7;
  /**
   * The longest a force is held while new regions are installed (Handover::kCarryMotion); a
   * supervisor held up longer (a secondary thread slow to join) gets the force released at the
   * engage rate meanwhile: a force without stiffness behind it is not held for long.
   */
  static constexpr double kMaxHold_s = 0.05;
  /** An idle primary thread comes round at least this often (stop, reconfiguration, watchdog). */
  static constexpr double kIdleWait_s = 0.02;

  /**
   * One primary period released at `release_ns`, run at `now_ns` (what the primary thread runs;
   * public for the allocation test). Never allocates, locks or throws.
   */
  void PrimaryPeriod(std::int64_t release_ns, std::int64_t now_ns) noexcept;
  /**
   * What a secondary region's thread asks before each step: false while it must stay parked (the
   * regions are going to sleep, or asleep; the first such call counts it as parked). While the
   * primary watches for rest, it also reports whether this region is at rest. Public, like
   * PrimaryPeriod, so a test can play the secondaries on one thread. Never allocates or blocks.
   */
  bool SecondaryMayStep(RegionIndex region) noexcept;

  static std::int64_t NowNs() noexcept;

 private:
  void PrimaryThread(std::int64_t origin_ns);
  void SecondaryThread(RegionIndex region, std::int64_t origin_ns);
  void StartSecondaries(std::int64_t origin_ns);
  void StopSecondaries();
  std::string ApplyRealtimeSettings(std::thread& thread) const;
  // `binding`: the sliding tool's proxy over `regions` (SlidingContact::Prepare), when it has one.
  void Install(const Scene& scene, std::unique_ptr<AsyncRegions> regions,
               std::optional<SlidingContact::Binding> binding);
  // The first release on the primary grid at or after `not_before_ns`.
  std::int64_t NextPrimaryRelease(std::int64_t not_before_ns) const;
  // Primary thread: sleeping at rest (see the class comment).
  void WatchForRest(bool touched) noexcept;
  void WakeSecondaries(std::int64_t origin_ns) noexcept;
  void WaitForInput() noexcept;
  // Primary thread: a newly latched fault counted, a latched one re-armed when it may be.
  void UpdateFaultState(const PortGuard::Output& sent) noexcept;
  // Primary thread, while the regions are its own: the coupling's energy balance watched.
  void WatchEnergyBalance() noexcept;
  // Primary thread: these regions' runaway counted (once), with the energies watched last.
  void PublishRunaway() noexcept;
  // Primary thread: the watch forgets the regions before (they restart from rest).
  void RestartEnergyWatch() noexcept;
  // Primary thread: one period's steps, the contact moved to `contact_m` over its substeps; the
  // reaction at the period's start, N.
  std::array<double, 3> StepPrimaryPeriod(const std::array<double, 3>& contact_m) noexcept;
  // Primary thread: the period's contact, from the tip (fresh) or held — the node's or the
  // sliding tool's.
  ContactTracker::Contact TrackContact(bool fresh, std::int64_t release_ns,
                                       const std::optional<LatticeIndex>& centre,
                                       bool usable) noexcept;
  // Primary thread: the node the contact wants the regions on, for the supervisor.
  void PublishContactRequest(const ContactTracker::Contact& contact) noexcept;
  // Primary thread: the period's reaction at its start — stepped on regions that are its own,
  // held while a pause holds it, else none.
  std::array<double, 3> PeriodReaction(bool usable, bool holding,
                                       const ContactTracker::Contact& contact,
                                       std::int64_t release_ns, std::int32_t* flags) noexcept;
  // Primary thread: the simulated force through the port guard, its flags and counts.
  PortGuard::Output GuardPeriod(std::int64_t now_ns, const std::array<double, 3>& simulated_n,
                                bool render, const ContactTracker::Contact& contact, bool have,
                                std::int32_t* flags) noexcept;
  // Primary thread: an input from the I/O thread (the resampler, the answers, the newest).
  void TakeInput(const DeviceSample& sample) noexcept;
  // Back to awake with nothing parked (supervisor, while the primary is paused or stopped).
  void ForgetSleep();
  // Primary thread: whether the regions are this period's (not paused by a reconfiguration, not
  // before new ones start); a pause's first period decides whether it holds the force.
  bool RegionsAreOurs(std::int64_t release_ns) noexcept;
  // Primary thread, the first period on new regions: the contact as Reconfigure's hand-over says.
  void ApplyRestart(std::int64_t release_ns) noexcept;
  // Primary thread: the period's answer to the I/O thread and its record to the black box.
  void PublishPeriod(std::int64_t now_ns, const std::array<double, 3>& force_n,
                     const std::array<double, 3>& raw_force_n, std::int32_t flags) noexcept;

  Scene scene_;
  Options options_;
  const ContactObject object_;  // the object as the tool meets it: the same for every configuration
  std::unique_ptr<AsyncRegions> regions_;
  // [0] the primary's (kept across reconfigurations: its period never changes), then one per
  // secondary region of the installed regions.
  std::vector<std::unique_ptr<DeadlineMonitor>> monitors_;
  // The loop's protocols between its threads, one type each (see each one's memory order):
  InputHandoff inputs_;                    // I/O → primary: every input, and the idle wait
  ForceRing forces_;                       // primary → I/O: the answers
  BlackBoxRing black_box_;                 // primary → supervisor: every period's record
  RegionHandover handover_;                // supervisor ↔ primary: a reconfiguration
  SecondaryParking<kMaxRegions> parking_;  // primary ↔ secondaries: sleeping at rest
  LoopCounters<kMaxRegions> counters_;     // region threads → anyone: counts and gauges
  // Supervisor → primary: the error and flags every answer carries (each a value of its own).
  Relaxed<double> error_percent_{-1};
  Relaxed<std::int32_t> error_flags_{0};
  double balance_peak_stored_j_ = 0;  // primary thread: since the regions last started from rest
  bool runaway_seen_ = false;         // primary thread: these regions' runaway is counted
  int runaway_periods_ = 0;           // primary thread: periods in a row above the watch's line
  // Primary thread, of these regions: whether the watch ran in this period, one bit per
  // watched period (newest lowest) set where the state was above its line, and what the watch
  // measured the last time it was. A divergence fault counts as their runaway once the state
  // was above the line in kFaultRunawayPeriods of the watch's last kRunawayPeriods periods.
  static constexpr int kFaultRunawayPeriods = 2;
  bool watched_this_period_ = false;
  std::uint32_t over_watch_line_ = 0;
  RunawayEnergies watched_;
  std::atomic<bool> running_{false}, stop_{false}, stop_secondaries_{false};
  std::thread primary_thread_;
  std::vector<std::thread> secondary_threads_;
  ReplacementTimes last_replacement_;
  std::vector<std::int64_t> lead_ns_;
  double tick_ns_ = 0;
  double primary_period_ns_ = 0;
  std::int64_t origin_ns_ = 0;         // the primary release grid: origin + k · period
  LatticeIndex centre_{};              // written only while the primary has paused the regions
  std::int64_t reconfigurations_ = 0;  // supervisor thread only
  // Held by the supervisor while it replaces regions_ (Install) and by the deformation thread
  // while it reads them (TakeSurface); never by a region thread.
  std::mutex surface_mutex_;
  std::int64_t installs_ = 0;  // under surface_mutex_

  // Primary thread: the last period's reaction and centre, for a pause that holds the force (the
  // regions and centre_ are the supervisor's while paused); whether this pause holds it (latched
  // at its first period), for how many periods so far, and whether the last period on the
  // regions was in contact.
  std::array<double, 3> held_reaction_{};
  LatticeIndex held_centre_{};
  bool holding_ = false, engaged_ = false;
  std::int64_t held_periods_ = 0;

  enum SleepState : int { kAwake, kParking, kAsleep };
  SleepState sleep_state_ = kAwake;  // primary thread (supervisor only while it is paused)

  // Input arrives with jitter: the tip the primary drives is the device's, resampled at each
  // release on the device's own timeline (one seq per primary period), continued for at most
  // this many periods past the newest input and then held.
  static constexpr int kMaxPredictedPeriods = 10;

  // Primary thread state. A sliding tool (contact.model = "proxy") touches through sliding_
  // instead of contact_; sliding_ is bound to the regions by Install.
  ContactTracker contact_;
  std::optional<SlidingContact> sliding_;
  PortGuard guard_;
  bool restarted_since_fault_ = false;  // the regions restarted from rest after the latch
  InputResampler tip_{1e-3, kMaxPredictedPeriods * 1e-3};  // re-made for the primary's period
  // The inputs taken since the last answer: the oldest, and whether they came one seq after
  // another (only then does an answer cover first_seq … seq).
  std::int64_t first_taken_seq_ = -1;
  bool taken_in_sequence_ = true;
  std::int64_t periods_run_ = 0;  // primary periods answered since the loop was made
  DeviceSample last_input_;
};

}  // namespace hapticsim
