#include "daemon/contact_tracker.hpp"

#include <algorithm>
#include <cmath>

namespace hapticsim {

ContactTracker::ContactTracker(const MeshSettings& mesh, double engage_ramp_s)
    : mesh_(mesh),
      h_(mesh.edge_m / (mesh.nodes - 1)),
      ramp_ns_(static_cast<std::int64_t>(engage_ramp_s * 1e9)) {}

LatticeIndex ContactTracker::NearestContactNode(
    const std::array<double, 3>& surface_point_m) const noexcept {
  const int last = mesh_.nodes - 1;
  LatticeIndex node{};
  for (int c = 0; c < 3; ++c) {
    node[c] = std::clamp(static_cast<int>(std::lround(surface_point_m[c] / h_)), 0, last);
  }
  if (IsSupportNode(mesh_, node)) {
    // A fixed corner cannot be driven: its free neighbour along the axis the point is farthest
    // from the corner on. The corner has every index on the boundary, so the neighbour keeps two
    // and stays on the surface.
    int axis = 0;
    double farthest = -1;
    for (int c = 0; c < 3; ++c) {
      const double off = std::abs(surface_point_m[c] / h_ - node[c]);
      if (off > farthest) farthest = off, axis = c;
    }
    node[axis] += node[axis] == 0 ? 1 : -1;
  }
  return node;
}

ContactTracker::Contact ContactTracker::Update(const std::array<double, 3>& tip_m,
                                               std::int64_t now_ns,
                                               const std::optional<LatticeIndex>& centre) noexcept {
  tip_ = tip_m;
  const bool after_gap = held_;
  held_ = false;
  const double edge = mesh_.edge_m;
  bool inside = true;
  for (double x : tip_m) inside = inside && x > 0 && x < edge;
  if (!inside) {
    state_ = State::kFree;
    std::array<double, 3> nearest = tip_m;
    for (double& x : nearest) x = std::clamp(x, 0.0, edge);
    wanted_ = NearestContactNode(nearest);
    return {};
  }
  if (state_ == State::kAwaitLiftOff) return {};
  if (state_ == State::kFree) {
    // Touch-down through the face the tip is least deep behind (front face first on a tie, as
    // InwardNormal orders them).
    int axis = 2;
    double face = 0, depth = tip_m[2];
    for (int c : {2, 0, 1}) {
      if (tip_m[c] < depth) depth = tip_m[c], axis = c, face = 0;
      if (edge - tip_m[c] < depth) depth = edge - tip_m[c], axis = c, face = edge;
    }
    entry_ = tip_m;
    entry_[axis] = face;
    inward_ = {0, 0, 0};
    inward_[axis] = face == 0 ? 1.0 : -1.0;
    node_ = NearestContactNode(entry_);
    wanted_ = node_;
    const bool centred = centre && *centre == node_;
    state_ = centred ? State::kEngaged : State::kWaiting;
    ramping_ = false;
    if (centred && depth > kDeepTouchDown_m) StartRamp({0, 0, 0}, now_ns);
  } else if (after_gap && state_ == State::kEngaged) {
    StartRamp(displacement_, now_ns);  // input back after a gap: from where the node was held
  }
  return Advance(now_ns, centre);
}

ContactTracker::Contact ContactTracker::Hold(std::int64_t now_ns,
                                             const std::optional<LatticeIndex>& centre) noexcept {
  if (state_ == State::kFree || state_ == State::kAwaitLiftOff) return {};
  held_ = state_ == State::kEngaged;
  return Advance(now_ns, centre);
}

void ContactTracker::StartRamp(const std::array<double, 3>& from_m, std::int64_t now_ns) noexcept {
  ramping_ = true;
  ramp_from_ = from_m;
  ramp_start_ns_ = now_ns;
}

ContactTracker::Contact ContactTracker::Advance(
    std::int64_t now_ns, const std::optional<LatticeIndex>& centre) noexcept {
  if (state_ == State::kWaiting && centre && *centre == node_) {
    // Engage late: the tip went on while the regions moved; ramp its depth in from zero.
    state_ = State::kEngaged;
    StartRamp({0, 0, 0}, now_ns);
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
    return contact;
  }
  // A ramp blends from its start displacement to the tip's by a smoothstep 3τ² − 2τ³: it starts
  // where the node was with zero velocity and ends with the tip's own, so neither the node's
  // velocity nor its position jumps (a velocity jump is an acceleration spike, and the node's
  // inertia would send it to the user as a force spike).
  double weight = 1;
  if (ramping_ && ramp_ns_ > 0) {
    const double tau = std::min(1.0, static_cast<double>(now_ns - ramp_start_ns_) / ramp_ns_);
    weight = tau * tau * (3 - 2 * tau);
    if (tau >= 1) ramping_ = false;
  }
  for (int c = 0; c < 3; ++c) {
    contact.displacement_m[c] = ramp_from_[c] + weight * (tip_[c] - entry_[c] - ramp_from_[c]);
  }
  if (!ramping_) ramp_from_ = {0, 0, 0};
  displacement_ = contact.displacement_m;
  return contact;
}

void ContactTracker::RestartFromRest() noexcept {
  state_ = State::kAwaitLiftOff;
  held_ = false;
}

void ContactTracker::RestartKeepingContact() noexcept {
  if (state_ == State::kEngaged) state_ = State::kWaiting;
  held_ = false;
}

}  // namespace hapticsim
