#include "daemon/contact_tracker.hpp"

#include <algorithm>
#include <cmath>

#include "daemon/smoothstep.hpp"

namespace hapticsim {
namespace {

std::array<double, 3> Minus(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}

}  // namespace

ContactTracker::ContactTracker(const ContactObject& object, double engage_ramp_s)
    : object_(object), ramp_ns_(static_cast<std::int64_t>(engage_ramp_s * 1e9)) {}

std::optional<LatticeIndex> ContactTracker::NearestContactNode(
    const std::array<double, 3>& surface_point_m) const noexcept {
  return object_.NearestDrivable(surface_point_m);
}

ContactTracker::Contact ContactTracker::Update(const std::array<double, 3>& tip_m,
                                               std::int64_t now_ns,
                                               const std::optional<LatticeIndex>& centre) noexcept {
  tip_ = tip_m;
  if (held_) fresh_tips_ = 0;  // a gap: its jump is the stale ramp's
  const bool after_gap = held_;
  held_ = false;
  if (!object_.Inside(tip_m)) {
    if (SlipsOff(tip_m, now_ns, after_gap)) return Advance(now_ns, centre);
    state_ = State::kFree;
    slipping_off_ = false;
    fresh_tips_ = 0;
    wanted_ = NearestContactNode(object_.NearestPoint(tip_m));
    return {};
  }
  if (slipping_off_) {
    if (ReentersThroughOwnNode(tip_m)) {
      // Back inside where it left: the node goes on from its own path to the tip again (the
      // tip's last step, from outside, is no jump to catch up with).
      slipping_off_ = false;
      fresh_tips_ = 0;
      CatchUp(OwnPathNow(now_ns), now_ns);
    } else if (GoesOnSlipping(now_ns, after_gap)) {
      // Back inside elsewhere (the next step of a staircase): the node goes on back to rest, and
      // the touch is a new one once it is there. Taken up, its node would be driven by the tip
      // less an entry point millimetres away (on the organ: up to 0.38 N sideways, for 150 ms,
      // at the port guard's ceiling).
      return Advance(now_ns, centre);
    } else {
      slipping_off_ = false;
      state_ = State::kFree;
      fresh_tips_ = 0;
    }
  }
  if (state_ == State::kAwaitLiftOff) return {};
  if (state_ == State::kFree) {
    // Touch-down through the face the tip is least deep behind (front face first on a tie, as
    // InwardNormal orders them).
    const ContactObject::Entry entry = object_.EntryOf(tip_m);
    entry_ = entry.point_m;
    inward_ = entry.inward_normal;
    const double depth = entry.depth_m;
    const std::optional<LatticeIndex> node = NearestContactNode(entry_);
    wanted_ = node;
    if (!node) {
      // On a held face: the tool touches the support, which is not rendered (ContactObject::
      // NearestDrivable); nothing until it has left the object.
      state_ = State::kAwaitLiftOff;
      return {};
    }
    node_ = *node;
    const bool centred = centre && *centre == node_;
    state_ = centred ? State::kEngaged : State::kWaiting;
    ramping_ = false;
    // The node starts at rest on the surface: no velocity from an earlier contact.
    displacement_ = velocity_ = {0, 0, 0};
    last_ns_ = 0;
    if (centred && depth > kDeepTouchDown_m) StartRamp({0, 0, 0}, {0, 0, 0}, ramp_ns_, now_ns);
  } else if (after_gap && state_ == State::kEngaged) {
    // Input back after a gap: from where the node was held, at rest.
    StartRamp(displacement_, {0, 0, 0}, ramp_ns_, now_ns);
  } else if (state_ == State::kEngaged && TipJumped(tip_m)) {
    // Input that came late by more than the resampler continues over (a driver that stalled for
    // a few milliseconds) moves the tip several periods' worth in one. The node catches up from
    // its own path instead, from where that path is now: on from the last period at its velocity.
    CatchUp(OwnPathNow(now_ns), now_ns);
  }
  tip_step_ = fresh_tips_ > 0 ? Minus(tip_m, last_tip_) : std::array<double, 3>{};
  last_tip_ = tip_m;
  fresh_tips_ = std::min(fresh_tips_ + 1, 2);
  return Advance(now_ns, centre);
}

ContactTracker::Contact ContactTracker::Hold(std::int64_t now_ns,
                                             const std::optional<LatticeIndex>& centre) noexcept {
  if (state_ == State::kFree || state_ == State::kAwaitLiftOff) return {};
  held_ = state_ == State::kEngaged;
  return Advance(now_ns, centre);
}

bool ContactTracker::SlipsOff(const std::array<double, 3>& tip_m, std::int64_t now_ns,
                              bool after_gap) noexcept {
  if (state_ != State::kEngaged) return false;
  if (slipping_off_) return GoesOnSlipping(now_ns, after_gap);
  // Outside the object but still pressed along the entry face's normal: the tip went off a
  // face sideways (over a step of a curved object's staircase, past its rim), not out of it.
  double pressed = 0, node_depth = 0;
  for (int c = 0; c < 3; ++c) {
    pressed += (tip_m[c] - entry_[c]) * inward_[c];
    node_depth += displacement_[c] * inward_[c];
  }
  if (pressed <= kDeepTouchDown_m || node_depth <= kDeepTouchDown_m) return false;
  slipping_off_ = true;
  StartRamp(OwnPathNow(now_ns), velocity_, kSlipOff_ns, now_ns);
  return true;
}

bool ContactTracker::GoesOnSlipping(std::int64_t now_ns, bool after_gap) noexcept {
  // Input back after a gap: the slip goes on from where the node was held, at rest.
  if (after_gap) StartRamp(displacement_, {0, 0, 0}, kSlipOff_ns, now_ns);
  return ramping_;  // until the node is back at rest
}

bool ContactTracker::ReentersThroughOwnNode(const std::array<double, 3>& tip_m) const noexcept {
  return NearestContactNode(object_.EntryOf(tip_m).point_m) == node_;
}

std::array<double, 3> ContactTracker::OwnPathNow(std::int64_t now_ns) const noexcept {
  const double dt = last_ns_ > 0 ? static_cast<double>(now_ns - last_ns_) * 1e-9 : 0.0;
  std::array<double, 3> here = displacement_;
  for (int c = 0; c < 3; ++c) here[c] += velocity_[c] * dt;
  return here;
}

bool ContactTracker::TipJumped(const std::array<double, 3>& tip_m) const noexcept {
  if (fresh_tips_ < 2) return false;  // a step to compare with needs two tips before this one
  for (int c = 0; c < 3; ++c) {
    if (std::abs(tip_m[c] - last_tip_[c] - tip_step_[c]) > kCatchUpJump_m) return true;
  }
  return false;
}

void ContactTracker::StartRamp(const std::array<double, 3>& from_m,
                               const std::array<double, 3>& velocity_m_per_s,
                               std::int64_t duration_ns, std::int64_t now_ns) noexcept {
  ramping_ = true;
  ramp_from_ = from_m;
  ramp_velocity_ = velocity_m_per_s;
  ramp_start_ns_ = now_ns;
  ramp_duration_ns_ = duration_ns;
}

std::array<double, 3> ContactTracker::OwnPathInside(double since_s) const noexcept {
  std::array<double, 3> path{};
  for (int c = 0; c < 3; ++c) path[c] = ramp_from_[c] + ramp_velocity_[c] * since_s;
  // A tool only pushes: the node it drives is never outside its face. A path going outwards
  // comes from a mispredicted tip (at a touch-down at 1 m/s the resampler put the tip 0.32 mm in
  // while the next inputs said 2 µm; going on at the −0.32 m/s of its way back, the blend pulled
  // the node 2.3 mm out of the object, and the port guard then damped its return with up to
  // 1.06 N). Where the path meets the face its normal velocity stops there: the one place a ramp
  // changes the node's velocity at once, by at most (1 − w) times the outward speed, which the
  // uncut path would have kept pulling the node out with.
  double outwards = 0;
  for (int c = 0; c < 3; ++c) outwards += path[c] * inward_[c];
  if (outwards < 0) {
    for (int c = 0; c < 3; ++c) path[c] -= outwards * inward_[c];
  }
  return path;
}

ContactTracker::Contact ContactTracker::Advance(
    std::int64_t now_ns, const std::optional<LatticeIndex>& centre) noexcept {
  if (state_ == State::kWaiting && centre && *centre == node_) {
    // Engage late: the tip went on while the regions moved; ramp its depth in from zero.
    state_ = State::kEngaged;
    StartRamp({0, 0, 0}, {0, 0, 0}, ramp_ns_, now_ns);
  }
  Contact contact;
  if (state_ == State::kWaiting) {
    contact.waiting = true;
    return contact;
  }
  contact.engaged = true;
  contact.inward_normal = inward_;
  if (held_) {  // no fresh tip: the node stays where it was
    contact.displacement_m = displacement_;
    for (int c = 0; c < 3; ++c) contact.point_m[c] = entry_[c] + displacement_[c];
    velocity_ = {0, 0, 0};
    last_ns_ = now_ns;
    return contact;
  }
  // A ramp blends from the node's own path (where it was, going on at the velocity it had) to the
  // tip's by a smoothstep w = 3τ² − 2τ³: it starts with the node's position and velocity and
  // ends with the tip's, so neither jumps (a velocity jump is an acceleration spike, and the
  // node's inertia would send it to the user as a force spike).
  double weight = 1, since_s = 0;
  if (ramping_ && ramp_duration_ns_ > 0) {
    const double tau =
        std::min(1.0, static_cast<double>(now_ns - ramp_start_ns_) / ramp_duration_ns_);
    weight = Smoothstep(tau);
    since_s = static_cast<double>(now_ns - ramp_start_ns_) * 1e-9;
    if (tau >= 1) ramping_ = false;
  }
  const std::array<double, 3> own_path = OwnPathInside(since_s);
  // Slipping off, the node goes back to rest (its own surface point) instead of to the tip.
  const double to_tip = slipping_off_ ? 0.0 : 1.0;
  for (int c = 0; c < 3; ++c) {
    contact.displacement_m[c] =
        (1 - weight) * own_path[c] + weight * to_tip * (tip_[c] - entry_[c]);
  }
  if (last_ns_ > 0 && now_ns > last_ns_) {
    const double dt = static_cast<double>(now_ns - last_ns_) * 1e-9;
    for (int c = 0; c < 3; ++c) velocity_[c] = (contact.displacement_m[c] - displacement_[c]) / dt;
  }
  last_ns_ = now_ns;
  displacement_ = contact.displacement_m;
  for (int c = 0; c < 3; ++c) contact.point_m[c] = entry_[c] + displacement_[c];
  return contact;
}

void ContactTracker::RestartFromRest() noexcept {
  state_ = State::kAwaitLiftOff;
  held_ = false;
  slipping_off_ = false;
}

void ContactTracker::RestartKeepingContact() noexcept {
  // Slipping off, the node was let go (the tip outside, or back inside elsewhere): nothing to
  // engage again (a tip inside touches down afresh at the next Update).
  if (slipping_off_) {
    state_ = State::kFree;
  } else if (state_ == State::kEngaged) {
    state_ = State::kWaiting;
  }
  held_ = false;
  slipping_off_ = false;
}

void ContactTracker::CatchUpFrom(const std::array<double, 3>& held_m,
                                 std::int64_t held_at_ns) noexcept {
  if (state_ != State::kEngaged) return;
  // The node's own path starts where it was held, so its velocity over the next period is the
  // one it had (velocity_: the tip's, which it followed until the hold).
  displacement_ = held_m;
  last_ns_ = held_at_ns;
  CatchUp(held_m, held_at_ns);
}

void ContactTracker::CatchUp(const std::array<double, 3>& from_m, std::int64_t from_ns) noexcept {
  // A ramp under way (an engagement, input back after a gap) keeps what is left of it: cut to
  // kCatchUp_ns it would bring the force in several times faster than it was meant to.
  std::int64_t duration = kCatchUp_ns;
  if (ramping_) duration = std::max(duration, ramp_start_ns_ + ramp_duration_ns_ - from_ns);
  StartRamp(from_m, velocity_, duration, from_ns);
}

}  // namespace hapticsim
