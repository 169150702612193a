#pragma once

#include <algorithm>
#include <array>
#include <cstdint>

namespace hapticsim {

/**
 * The device profile: what the force sent to the device may do ([device] in the daemon config).
 * The defaults suit a desktop device rated 3–9 N peak; docs/operations.md lists profiles.
 */
struct PortGuardSettings {
  double max_force_n = 8.0;              ///< magnitude ceiling: larger forces are saturated
  double max_force_rate_n_per_ms = 0.5;  ///< slew ceiling between consecutive periods, N per ms
  double engage_rate_n_per_ms = 0.05;    ///< engaging and releasing ramp (from and to zero)
  double lift_off_rate_n_per_ms = 0.1;   ///< a lift-off's release (or the engage ramp's if faster)
  double fault_force_n = 50.0;           ///< a simulated force above this is a divergence: fault
  double watchdog_s = 0.2;               ///< a primary gap this long while sending force: fault
  bool passivity = true;                 ///< time-domain passivity observer and controller
  double max_damping_n_s_per_m = 10.0;   ///< the most damping the controller may add

  /** The rate a lift-off releases at: lift_off_rate_n_per_ms, or the engage ramp's if faster,
   *  at most the slew ceiling, N per ms. */
  double LiftOffRate() const {
    return std::min(max_force_rate_n_per_ms,
                    std::max(lift_off_rate_n_per_ms, engage_rate_n_per_ms));
  }
};

/**
 * The force-safety layer between the primary region and the device port: whatever the simulation,
 * the threads or the input do, the force sent stays inside the device's envelope and the port
 * does not create energy. Plain logic for the primary thread: no allocation, no locks, no
 * exceptions, no I/O.
 *
 * Each period it takes the simulated force on the user, whether that force may be rendered (in
 * contact, fresh input, regions running), whether the contact is engaged, and where the contact
 * point is, and returns the force to send. In this order:
 *
 *  1. Faults latch. A non-finite simulated force, one above fault_force_n (a diverging
 *     simulation), or a gap of more than watchdog_s between primary periods while force is being
 *     sent latches a fault: the output releases to zero and stays there until Rearm().
 *  2. Unilateral contact. The normal force never pulls the tool into the surface: a component
 *     along the contact's inward normal is removed.
 *  3. Envelope. The magnitude is saturated at max_force_n.
 *  4. Engagement. Whenever rendering starts or stops, or the simulation restarts under it
 *     (Reengage), the output moves to the new target (the simulated force, or zero) at
 *     engage_rate_n_per_ms at most, so every engagement (start-up, a new session, input back
 *     after a gap, a re-arm, a reconfiguration) ramps from zero and every release ramps to zero;
 *     a lift-off releases faster, at lift_off_rate_n_per_ms (the tool has left; what it still
 *     had is mostly the sideways pull of a node dragged along, which no step should drop at the
 *     slew ceiling). A touch-down whose force is still within one ramp step needs no ramp: a
 *     normal touch renders unchanged.
 *  5. Passivity (Hannaford and Ryu's time-domain passivity observer and controller, in
 *     impedance form). The observer sums the energy the port has absorbed since the touch-down,
 *     E = −Σ F_sent(k−1) · (p(k) − p(k−1)), the exact work a force held over each period does on
 *     a contact point moving from p(k−1) to p(k). A passive environment keeps E ≥ 0. Before
 *     sending F, the controller predicts the next period's motion Δp from the last
 *     kVelocityPeriods periods; if F · Δp (the energy F would give the user) exceeds E, it lowers
 *     the force along Δp so that F · Δp = E, taking away exactly the excess. With E < 0 (the
 *     prediction was short) that is damping, bounded by max_damping_n_s_per_m: the deficit is
 *     taken back over the next periods rather than by one unbounded force. What it leaves obeys
 *     2 and 3 again.
 *  6. Slew. The change from the last force sent is at most max_force_rate_n_per_ms per
 *     millisecond of wall time (as are the ramps of 4): missed periods run back to back within
 *     microseconds move the force by little.
 *
 * Every period where 2, 3, 4 or 6 changed the force is counted as limited; 5 is counted as
 * dissipating, its energy summed in joules. The caller flags both on the force sent (the
 * looked-up error no longer describes it).
 */
class PortGuard {
 public:
  enum class Fault : int { kNone = 0, kNonFinite, kDivergence, kWatchdog };

  struct Output {
    std::array<double, 3> force_n{};
    bool limited = false;            ///< envelope, unilateral, ramp or slew changed the force
    bool dissipating = false;        ///< the passivity controller took energy out this period
    bool latched = false;            ///< a fault holds the output at (or on its way to) zero
    Fault new_fault = Fault::kNone;  ///< the fault latched in this period, if any
  };

  /** One period's input. */
  struct Input {
    std::int64_t now_ns = 0;              ///< when this period runs (CLOCK_MONOTONIC)
    std::array<double, 3> simulated_n{};  ///< the simulation's force on the user
    bool render = false;                  ///< the simulated force may be sent
    bool engaged = false;                 ///< the contact is engaged (rendered or not)
    std::array<double, 3> position_m{};   ///< the device's newest received position
    bool have_position = false;
    std::array<double, 3> inward_normal{};  ///< the contact surface's, into the object (0: none)
  };

  /**
   * kOffForTests (hapticsimd --no-port-guard, which only a sandbox may run): the simulated force
   * goes out as it is, with only 1 (faults) and 4 (the engagement ramps) left: no unilateral
   * cut, envelope, passivity controller or slew. A soak shows with it that the regions'
   * coupling holds by itself, not because this class hides what it does.
   */
  enum class Mode { kGuarded, kOffForTests };

  PortGuard(const PortGuardSettings& settings, double period_s,
            Mode mode = Mode::kGuarded) noexcept;

  Output Period(const Input& in) noexcept;

  /** Clears a latched fault: the caller has restarted the simulation from rest and the tool is
   * out of contact. The next engagement ramps from zero. */
  void Rearm() noexcept;

  /** The simulation restarted from rest under the force being sent (new regions, a reset): move
   * to its new force at the engage rate, as after any engagement. The contact point's path and
   * the port's energy start afresh (the point's jump to where the restart put it is no motion of
   * the port, and the tissue at rest stores nothing). */
  void Reengage() noexcept;

  bool latched() const noexcept { return latched_; }
  bool guarded() const noexcept { return guarded_; }
  /** Energy the port has absorbed since the current engagement began, J (the observer's E). */
  double port_energy_j() const noexcept { return energy_j_; }
  /** Energy the passivity controller has dissipated since construction, J. */
  double dissipated_j() const noexcept { return dissipated_j_; }
  const PortGuardSettings& settings() const noexcept { return settings_; }

  /** Periods the controller's velocity estimate spans (the device's jitter averages out). */
  static constexpr int kVelocityPeriods = 4;

 private:
  using Vec = std::array<double, 3>;
  void Latch(Fault fault, Output* out) noexcept;
  void CheckFaults(const Input& in, Output* out) noexcept;
  // The observer: the work the force sent last period did on the contact point since.
  void Observe(const Input& in) noexcept;
  // Unilateral contact and the magnitude ceiling; true when either changed the force.
  bool Envelope(const Vec& normal, Vec* force) const noexcept;
  // The passivity controller; true when it took energy out.
  bool Dissipate(const Vec& normal, Vec* force) noexcept;
  Vec PredictedStep() const noexcept;

  PortGuardSettings settings_;
  double period_ms_;
  bool guarded_ = true;  // Mode::kGuarded
  bool latched_ = false;
  std::array<double, 3> sent_{};        // the force sent last period
  std::array<double, 3> correction_{};  // what the controller took off it (its damping)
  bool engaging_ = false;               // ramping towards the target at the engage rate
  bool rendering_before_ = false;       // the last period rendered the simulated force
  bool engaged_before_ = false;         // the contact was engaged last period
  double energy_j_ = 0;                 // the observer's E since the engagement began
  double dissipated_j_ = 0;
  std::int64_t last_now_ns_ = 0;
  // The newest kVelocityPeriods + 1 received positions, one per period (a ring).
  std::array<std::array<double, 3>, kVelocityPeriods + 1> positions_{};
  int positions_held_ = 0;
  int next_position_ = 0;
};

}  // namespace hapticsim
