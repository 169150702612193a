#include "daemon/port_guard.hpp"

#include <algorithm>
#include <cmath>

namespace hapticsim {
namespace {

using Vec = std::array<double, 3>;

double Dot(const Vec& a, const Vec& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
double Norm(const Vec& a) { return std::sqrt(Dot(a, a)); }
bool Finite(const Vec& a) {
  return std::isfinite(a[0]) && std::isfinite(a[1]) && std::isfinite(a[2]);
}

// `from` moved towards `to` by at most `step` (as a vector: the direction is kept).
Vec StepTowards(const Vec& from, const Vec& to, double step, bool* reached) {
  const Vec d{to[0] - from[0], to[1] - from[1], to[2] - from[2]};
  const double length = Norm(d);
  *reached = length <= step;
  if (*reached) return to;
  const double s = step / length;
  return {from[0] + s * d[0], from[1] + s * d[1], from[2] + s * d[2]};
}

}  // namespace

PortGuard::PortGuard(const PortGuardSettings& settings, double period_s, Mode mode) noexcept
    : settings_(settings), period_ms_(period_s * 1e3), guarded_(mode == Mode::kGuarded) {}

void PortGuard::Latch(Fault fault, Output* out) noexcept {
  if (latched_) return;
  latched_ = true;
  out->new_fault = fault;
}

void PortGuard::Rearm() noexcept {
  latched_ = false;
  rendering_before_ = false;
  engaging_ = false;
  energy_j_ = 0;
}

void PortGuard::Reengage() noexcept {
  engaging_ = true;
  positions_held_ = 0;
  energy_j_ = 0;  // the simulation restarted from rest: it stores nothing
}

Vec PortGuard::PredictedStep() const noexcept {
  if (positions_held_ <= kVelocityPeriods) return {0, 0, 0};
  const int newest = (next_position_ + kVelocityPeriods) % (kVelocityPeriods + 1);
  const int oldest = next_position_;  // the ring is full: the next slot holds the oldest
  Vec step{};
  for (int c = 0; c < 3; ++c) {
    step[c] = (positions_[newest][c] - positions_[oldest][c]) / kVelocityPeriods;
  }
  return step;
}

void PortGuard::CheckFaults(const Input& in, Output* out) noexcept {
  // A stalled primary (the device held the last force meanwhile), a simulated force no tissue
  // gives.
  if (Norm(sent_) > 0 && last_now_ns_ != 0 &&
      static_cast<double>(in.now_ns - last_now_ns_) > settings_.watchdog_s * 1e9) {
    Latch(Fault::kWatchdog, out);
  }
  if (in.render && !Finite(in.simulated_n)) Latch(Fault::kNonFinite, out);
  if (in.render && Norm(in.simulated_n) > settings_.fault_force_n) Latch(Fault::kDivergence, out);
}

void PortGuard::Observe(const Input& in) noexcept {
  if (in.engaged && !engaged_before_) energy_j_ = 0;  // a touch-down: nothing stored yet
  engaged_before_ = in.engaged;
  if (!in.have_position) return;
  if (positions_held_ > 0) {
    const Vec& last = positions_[(next_position_ + kVelocityPeriods) % (kVelocityPeriods + 1)];
    const Vec moved{in.position_m[0] - last[0], in.position_m[1] - last[1],
                    in.position_m[2] - last[2]};
    energy_j_ -= Dot(sent_, moved);
    // What the controller's correction kept from the user over the same motion: dissipated.
    dissipated_j_ += Dot(correction_, moved);
  }
  positions_[next_position_] = in.position_m;
  next_position_ = (next_position_ + 1) % (kVelocityPeriods + 1);
  if (positions_held_ <= kVelocityPeriods) ++positions_held_;
}

bool PortGuard::Envelope(const Vec& normal, Vec* force) const noexcept {
  bool limited = false;
  const double pull = Dot(*force, normal);  // unilateral: no pull into the surface
  if (pull > 0) {
    for (int c = 0; c < 3; ++c) (*force)[c] -= pull * normal[c];
    limited = true;
  }
  const double magnitude = Norm(*force);
  if (magnitude > settings_.max_force_n) {
    for (double& f : *force) f *= settings_.max_force_n / magnitude;
    limited = true;
  }
  return limited;
}

bool PortGuard::Dissipate(const Vec& normal, Vec* force) noexcept {
  correction_ = {0, 0, 0};
  const Vec step = PredictedStep();
  const double length = Norm(step);
  if (length <= 1e-9) return false;  // a tool held still takes no energy, whatever the force
  const Vec along{step[0] / length, step[1] / length, step[2] / length};
  const double current = Dot(*force, along);
  if (current * length <= energy_j_) return false;
  // Down to what the budget allows; with a deficit (E < 0) that is damping, at most max_damping:
  // a short predicted step must not call for an unbounded force.
  const double floor = -settings_.max_damping_n_s_per_m * length / (period_ms_ * 1e-3);
  const double allowed = std::max(energy_j_ / length, floor);
  if (allowed >= current) return false;
  const Vec before = *force;
  for (int c = 0; c < 3; ++c) (*force)[c] += (allowed - current) * along[c];
  Envelope(normal, force);  // damping never pulls, and stays within the ceiling
  for (int c = 0; c < 3; ++c) correction_[c] = before[c] - (*force)[c];
  return true;
}

PortGuard::Output PortGuard::Period(const Input& in) noexcept {
  Output out;
  CheckFaults(in, &out);
  // Steps and ramps are per millisecond of wall time: missed periods run back to back (within
  // microseconds) move the force by little, not by a period's allowance each.
  const double elapsed_ms =
      last_now_ns_ == 0
          ? period_ms_
          : std::clamp(static_cast<double>(in.now_ns - last_now_ns_) * 1e-6, 0.0, period_ms_);
  last_now_ns_ = in.now_ns;
  Observe(in);

  const bool rendering = in.render && !latched_;
  const double ramp_step = settings_.engage_rate_n_per_ms * elapsed_ms;
  double release_step = ramp_step;
  Vec target{0, 0, 0};
  if (rendering) {
    target = in.simulated_n;
    out.limited = guarded_ && Envelope(in.inward_normal, &target);
    // Rendering again after a release that ran out: ramp in unless the force is within a step.
    if (!rendering_before_ && Norm(sent_) == 0 && !engaging_) {
      engaging_ = Norm(target) > ramp_step;
    }
  } else if (Norm(sent_) > 0) {
    engaging_ = true;  // releasing: to zero
    // Lift-off (the tool left the object) releases faster than the engage ramp, but not at the
    // slew ceiling: a node dragged along its face and lifted out still pulls sideways (0.5 N on
    // the organ's walk), and dropping that at once is a step the hand feels. A fault, stale input
    // or paused regions release at the engage rate, since the tool may still be pressing.
    if (!in.engaged && !latched_) release_step = settings_.LiftOffRate() * elapsed_ms;
  }
  rendering_before_ = rendering;

  Vec force = target;
  if (engaging_) {
    bool reached = false;
    force = StepTowards(sent_, target, rendering ? ramp_step : release_step, &reached);
    engaging_ = !reached;
    out.limited = out.limited || !reached;
  }
  if (rendering && settings_.passivity && guarded_) {
    out.dissipating = Dissipate(in.inward_normal, &force);
  } else {
    correction_ = {0, 0, 0};
  }

  bool within = true;
  const Vec slewed =
      guarded_ ? StepTowards(sent_, force, settings_.max_force_rate_n_per_ms * elapsed_ms, &within)
               : force;
  if (!within) out.limited = true;
  sent_ = Finite(slewed) ? slewed : Vec{0, 0, 0};
  out.force_n = sent_;
  out.latched = latched_;
  return out;
}

}  // namespace hapticsim
