#include "daemon/port_guard.hpp"

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

PortGuard::PortGuard(const PortGuardSettings& settings, double period_s) noexcept
    : settings_(settings), period_ms_(period_s * 1e3) {}

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

PortGuard::Output PortGuard::Period(const Input& in) noexcept {
  Output out;
  const bool sending = Norm(sent_) > 0;
  // 1. Faults: a stalled primary (the device held the last force meanwhile) or a simulated force
  //    no tissue gives.
  if (sending && last_now_ns_ != 0 &&
      static_cast<double>(in.now_ns - last_now_ns_) > settings_.watchdog_s * 1e9) {
    Latch(Fault::kWatchdog, &out);
  }
  last_now_ns_ = in.now_ns;
  if (in.render && !Finite(in.simulated_n)) Latch(Fault::kNonFinite, &out);
  if (in.render && Norm(in.simulated_n) > settings_.fault_force_n) {
    Latch(Fault::kDivergence, &out);
  }

  // The observer: the work the force sent last period did on the device since.
  if (in.have_position) {
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

  const bool rendering = in.render && !latched_;
  const double ramp_step = settings_.engage_rate_n_per_ms * period_ms_;
  Vec target{0, 0, 0};
  if (rendering) {
    target = in.simulated_n;
    // 2. Unilateral: no pull into the surface along its normal.
    const double pull = Dot(target, in.inward_normal);
    if (pull > 0) {
      for (int c = 0; c < 3; ++c) target[c] -= pull * in.inward_normal[c];
      out.limited = true;
    }
    // 3. The magnitude ceiling.
    const double magnitude = Norm(target);
    if (magnitude > settings_.max_force_n) {
      for (double& f : target) f *= settings_.max_force_n / magnitude;
      out.limited = true;
    }
    if (!rendering_before_ && !sending && !engaging_) {
      energy_j_ = 0;  // a new engagement: the port starts with nothing stored
      engaging_ = Norm(target) > ramp_step;
    }
  } else if (sending) {
    engaging_ = true;  // releasing: to zero at the same rate
  }

  // 4. Engagement and release ramps.
  Vec force = target;
  if (engaging_) {
    bool reached = false;
    force = StepTowards(sent_, target, ramp_step, &reached);
    if (reached) {
      engaging_ = false;
    } else {
      out.limited = true;
    }
  }

  correction_ = {0, 0, 0};
  // 5. Passivity: the energy the force would give the user over the next period stays within what
  //    the port has absorbed. Only the force along the predicted motion changes: down to what the
  //    budget allows, and with a deficit (E < 0) into damping — at most max_damping, so a short
  //    predicted step cannot call for an unbounded force.
  if (rendering && settings_.passivity) {
    const Vec step = PredictedStep();
    const double length = Norm(step);
    if (length > 1e-9) {
      const Vec along{step[0] / length, step[1] / length, step[2] / length};
      const double current = Dot(force, along);
      if (current * length > energy_j_) {
        const double damping_floor = -settings_.max_damping_n_s_per_m * length / (period_ms_ * 1e-3);
        const double allowed = std::max(energy_j_ / length, damping_floor);
        if (allowed < current) {
          const Vec before = force;
          for (int c = 0; c < 3; ++c) force[c] += (allowed - current) * along[c];
          out.dissipating = true;
          // Damping never pulls the tool into the surface either.
          const double pull = Dot(force, in.inward_normal);
          if (pull > 0) {
            for (int c = 0; c < 3; ++c) force[c] -= pull * in.inward_normal[c];
          }
          for (int c = 0; c < 3; ++c) correction_[c] = before[c] - force[c];
        }
      }
    }
  }

  rendering_before_ = rendering;

  // 6. Slew.
  bool within = false;
  const Vec slewed =
      StepTowards(sent_, force, settings_.max_force_rate_n_per_ms * period_ms_, &within);
  if (!within) out.limited = true;
  sent_ = Finite(slewed) ? slewed : Vec{0, 0, 0};
  out.force_n = sent_;
  out.latched = latched_;
  return out;
}

}  // namespace hapticsim
