#include "daemon/sliding_contact.hpp"

#include <algorithm>
#include <cmath>

#include "core/error.hpp"
#include "core/regions/proxy_following.hpp"
#include "daemon/smoothstep.hpp"

namespace hapticsim {
namespace {

bool Pushes(const std::array<double, 3>& push) {
  return push[0] != 0 || push[1] != 0 || push[2] != 0;
}

}  // namespace

SlidingContact::SlidingContact(const ContactObject& object, const ContactSettings& settings,
                               double engage_ramp_s)
    : object_(object),
      settings_(settings),
      ramp_ns_(static_cast<std::int64_t>(engage_ramp_s * 1e9)) {}

ContactObject::Entry SlidingContact::OnTouchedFace(
    const std::array<double, 3>& point_m) const noexcept {
  ContactObject::Entry entry{point_m, inward_, 0};
  for (int c = 0; c < 3; ++c) {
    if (inward_[c] != 0) entry.point_m[c] = face_m_;
  }
  return entry;
}

std::optional<LatticeIndex> SlidingContact::NodeInsideFace(
    const ContactObject::Entry& entry) const noexcept {
  const std::optional<LatticeIndex> node = NearestNodeInsideFace(entry);
  // On a held face: none (the support is not rendered).
  if (!node || !object_.Drivable(*node)) return std::nullopt;
  return node;
}

std::optional<LatticeIndex> SlidingContact::NearestNodeInsideFace(
    const ContactObject::Entry& entry) const noexcept {
  // The node of the entry's face plane nearest to the point, or the nearest of its eight
  // neighbours in the plane, that lies inside a flat face with the entry's normal (off the face's
  // rim, and off any step of the surface: a proxy slides on one flat face). The point is on the
  // plane (callers with a tip under the face project it: OnTouchedFace).
  int axis = 0;
  while (axis < 2 && entry.inward_normal[axis] == 0) ++axis;
  const int u = (axis + 1) % 3, v = (axis + 2) % 3;
  std::array<double, 3> at{};  // the point in lattice units
  LatticeIndex rounded{};
  for (int c = 0; c < 3; ++c) {
    at[c] = entry.point_m[c] / object_.spacing_m();
    rounded[c] = static_cast<int>(std::lround(at[c]));
  }
  std::optional<LatticeIndex> best;
  double best_d2 = 0;
  for (int du = -1; du <= 1; ++du) {
    for (int dv = -1; dv <= 1; ++dv) {
      LatticeIndex node = rounded;
      node[u] += du;
      node[v] += dv;
      if (object_.FlatFaceNormal(node) != entry.inward_normal) continue;
      const double d2 =
          (node[u] - at[u]) * (node[u] - at[u]) + (node[v] - at[v]) * (node[v] - at[v]);
      if (!best || d2 < best_d2) best = node, best_d2 = d2;
    }
  }
  return best;
}

SlidingContact::Binding SlidingContact::Prepare(const AsyncRegions& regions) const {
  const RegionPartition& partition = regions.partition();
  HAPTICSIM_THROW_UNLESS(partition.proxy_contact(),
                         "internal: a sliding contact on regions built for a driven node");
  Binding binding;
  binding.centre = partition.contact_node();
  const std::array<double, 3> normal = partition.contact_normal();
  int axes = 0;
  for (double c : normal) axes += c != 0 ? 1 : 0;
  if (axes != 1) return binding;  // regions on an edge: a touch waits for them on its face
  binding.proxy.emplace(partition.PrimaryProxySurface(), binding.centre, normal, settings_);
  HAPTICSIM_THROW_UNLESS(binding.proxy->loaded_dofs() == regions.proxy_loaded_dofs(),
                         "internal: the proxy and the primary region load different nodes");
  return binding;
}

void SlidingContact::Bind(Binding binding) noexcept {
  // On the face the proxy was on it goes on where it is; elsewhere it starts at the new centre
  // (and an engaged contact on another face waits: StepPeriod).
  if (binding.proxy && proxy_) binding.proxy->ContinueFrom(*proxy_);
  proxy_ = std::move(binding.proxy);
  bound_centre_ = binding.centre;
  ++bindings_;
}

SlidingContact::Contact SlidingContact::Update(const std::array<double, 3>& tip_m,
                                               std::int64_t now_ns,
                                               const std::optional<LatticeIndex>& centre) noexcept {
  last_tool_ = state_ == State::kEngaged ? tool_ : tip_m;
  tool_ = tip_m;
  if (state_ == State::kEngaged && !object_.Inside(tip_m) && PressedIn(tip_m)) {
    Release(now_ns);  // out sideways, still pressed in: the push fades out
  }
  if (state_ == State::kReleasing) {                 // wherever the tip goes (StepPeriod ends it)
    if (!object_.Inside(tip_m)) wall_within_m_ = 0;  // out of the wall: a touch is from outside
    return Answer();
  }
  if (!object_.Inside(tip_m)) {
    state_ = State::kFree;
    wall_within_m_ = 0;
    following_ = out_of_region_ = false;
    ramp_start_ns_ = catch_up_ns_ = -1;
    wanted_ = NodeInsideFace(object_.HoverEntry(tip_m));
    return {};
  }
  if (state_ == State::kAwaitLiftOff) {
    TouchTheWall(tip_m, now_ns, centre);
    return Answer();
  }
  if (state_ == State::kFree) {
    TouchDown(tip_m, now_ns, centre);
  } else if (state_ == State::kWaiting) {
    TryEngage(centre, now_ns);
  }
  return Answer();
}

void SlidingContact::TouchDown(const std::array<double, 3>& tip_m, std::int64_t now_ns,
                               const std::optional<LatticeIndex>& centre) noexcept {
  // Through the face the tip is least deep behind; where that face has no node inside it to
  // slide on — a riser of a voxel staircase one voxel high has rim nodes only (on the organ a
  // quarter of the tips inside came in so, and the tool pushed nothing until it left again) — the
  // next way out that has one, up to a voxel deeper. Never the face opposite the way in (on a
  // feature a voxel thin it is that near): its push would go the way the tool moves, pulling the
  // hand through the object. A held face ends the search: the support is not rendered, and a
  // side face beside it would push the tool sideways by as much as a voxel's depth.
  const std::array<ContactObject::Entry, 6> ways = object_.WaysOut(tip_m);
  ContactObject::Entry entry = ways[0];
  wanted_ = std::nullopt;
  for (const ContactObject::Entry& way : ways) {
    if (way.depth_m > ways[0].depth_m + object_.spacing_m()) break;
    bool opposite = true;
    for (int c = 0; c < 3; ++c)
      opposite = opposite && way.inward_normal[c] == -ways[0].inward_normal[c];
    if (opposite) continue;
    const std::optional<LatticeIndex> node = NearestNodeInsideFace(way);
    if (!node) continue;  // nothing inside it to slide on: the next way out
    if (object_.Drivable(*node)) {
      entry = way;
      wanted_ = node;
    }
    break;
  }
  TouchThrough(entry, wanted_, now_ns, centre);
}

void SlidingContact::TouchThrough(const ContactObject::Entry& entry,
                                  const std::optional<LatticeIndex>& node, std::int64_t now_ns,
                                  const std::optional<LatticeIndex>& centre) noexcept {
  wanted_ = node;
  wall_within_m_ = 0;
  inward_ = entry.inward_normal;
  for (int c = 0; c < 3; ++c) {
    if (inward_[c] != 0) face_m_ = entry.point_m[c];
  }
  if (!wanted_) {  // a held face: the support is not rendered (ContactTracker)
    state_ = State::kAwaitLiftOff;
    return;
  }
  state_ = State::kWaiting;
  TryEngage(centre, now_ns);
  // Engaged at once from outside, the spring starts at the surface: no ramp unless it is deep.
  if (state_ == State::kEngaged && entry.depth_m <= ContactTracker::kDeepTouchDown_m) {
    ramp_start_ns_ = -1;
  }
}

void SlidingContact::TouchTheWall(const std::array<double, 3>& tip_m, std::int64_t now_ns,
                                  const std::optional<LatticeIndex>& centre) noexcept {
  // Let go where the tool rose out of its face into a wall (the proxy slides on one face), the
  // tip inside the wall touches it, as from outside — through the wall's own face, never another
  // (the nearest way out may be the far side of a ridge, pushing the hand through it) — once
  // that way out is at most twice as deep as the tip was past the wall's foot then: its force
  // ramps in to about the push let go (the same spring, as deep in the same wall), or what the
  // hand pushed in since. Deeper, a touch could push far harder than the corner did: it waits,
  // until the tip comes back within that or leaves the object.
  if (wall_within_m_ <= 0) return;
  for (const ContactObject::Entry& way : object_.WaysOut(tip_m)) {
    if (way.inward_normal != wall_inward_) continue;
    if (way.depth_m > wall_within_m_) return;
    if (const std::optional<LatticeIndex> node = NodeInsideFace(way)) {
      TouchThrough(way, node, now_ns, centre);
    }
    return;
  }
}

SlidingContact::Contact SlidingContact::Hold(std::int64_t now_ns,
                                             const std::optional<LatticeIndex>& centre) noexcept {
  last_tool_ = tool_;
  if (state_ == State::kWaiting) TryEngage(centre, now_ns);
  return Answer();
}

void SlidingContact::TryEngage(const std::optional<LatticeIndex>& centre,
                               std::int64_t now_ns) noexcept {
  // Only on regions that are this period's (`centre`): while they are replaced, Bind writes proxy_.
  // Wherever the bound primary can push under the tip — on its node, or off it within the
  // primary's reach (then the regions follow it from there) — not only on the node it wants.
  if (!centre || !proxy_ || proxy_->inward_normal() != inward_ || !proxy_->CanTouchAt(tool_)) {
    return;
  }
  proxy_->PlaceUnder(tool_);
  last_tool_ = stepped_tool_ = tool_;
  pushed_n_ = {};
  state_ = State::kEngaged;
  out_of_region_ = following_ = false;
  catch_up_ns_ = -1;
  ramp_start_ns_ = now_ns;  // from waiting; a touch engaged at once from outside clears it
}

SlidingContact::Contact SlidingContact::Answer() const noexcept {
  Contact contact;
  if (state_ == State::kFree || state_ == State::kAwaitLiftOff) return contact;
  contact.engaged = state_ == State::kEngaged || state_ == State::kReleasing;
  contact.waiting = state_ == State::kWaiting || out_of_region_;
  contact.following = following_;
  contact.inward_normal = inward_;
  contact.point_m = tool_;  // the port moves with the hand: the spring's end the user holds
  return contact;
}

double SlidingContact::CatchUpLag(std::int64_t now_ns) const noexcept {
  if (catch_up_ns_ < 0 || now_ns - catch_up_ns_ >= catch_up_duration_ns_) return 0.0;
  const double tau = static_cast<double>(now_ns - catch_up_ns_) / catch_up_duration_ns_;
  return 1.0 - Smoothstep(tau);
}

double SlidingContact::RampScale(std::int64_t now_ns) const noexcept {
  if (ramp_start_ns_ < 0 || ramp_ns_ <= 0) return 1.0;
  const double tau = std::clamp(static_cast<double>(now_ns - ramp_start_ns_) / ramp_ns_, 0.0, 1.0);
  return Smoothstep(tau);
}

std::array<double, 3> SlidingContact::Rendered(const ProxyContact::Result& touch,
                                               std::int64_t now_ns) noexcept {
  // The push p is the spring's, ramped in (k scaled), taken at the step's end where p has moved
  // the surface by C·p: p = k·(offset − C·p).
  const double k = RampScale(now_ns) * settings_.stiffness_n_per_m;
  const double over = 1.0 + k * touch.compliance_m_per_n;
  std::array<double, 3> offset = touch.offset_m;
  const double lag = CatchUpLag(now_ns);
  if (lag > 0 && k > 0) {
    // Catching up after a pause, the spring pulls from where it gave the held push, and that
    // point goes back to the tool: offset − lag·δ, δ set so that the first push is the held
    // one (the tool the proxy follows lags as well: StepPeriod; δ is what the new regions' own
    // response differs by). The spring stays stiff throughout: a held force blended out without
    // it drove a light node through the surface under the tool. What the fading δ adds is kept
    // inside the friction cone (InsideFrictionCone): the user never feels more than μ_s times the
    // normal force.
    if (!catch_up_anchored_) {
      for (int c = 0; c < 3; ++c) catch_up_offset_m_[c] = offset[c] - held_push_[c] * over / k;
      catch_up_anchored_ = true;
    }
    for (int c = 0; c < 3; ++c) offset[c] -= lag * catch_up_offset_m_[c];
  }
  std::array<double, 3> push{};
  for (int c = 0; c < 3; ++c) push[c] = k * offset[c] / over;
  return InsideFrictionCone(push, touch.wall_holds);
}

std::array<double, 3> SlidingContact::InsideFrictionCone(
    const std::array<double, 3>& push, const std::array<bool, 3>& wall_holds) const noexcept {
  double normal = 0;
  for (int c = 0; c < 3; ++c) normal += push[c] * inward_[c];
  if (!(normal > 0)) return {};  // a push never pulls the tool in
  // What a wall holds (the proxy at its foot, the tool past it) is the wall's push, kept whole.
  std::array<double, 3> tangential{};
  for (int c = 0; c < 3; ++c) {
    tangential[c] = wall_holds[static_cast<std::size_t>(c)] ? 0.0 : push[c] - normal * inward_[c];
  }
  const double along = std::hypot(tangential[0], tangential[1], tangential[2]);
  const double most = settings_.static_friction * normal;
  if (along <= most) return push;
  std::array<double, 3> inside = push;
  for (int c = 0; c < 3; ++c) {
    if (!wall_holds[static_cast<std::size_t>(c)]) {
      inside[c] = normal * inward_[c] + tangential[c] * (most / along);
    }
  }
  return inside;
}

std::array<double, 3> SlidingContact::StepPeriod(AsyncRegions& regions,
                                                 std::int64_t now_ns) noexcept {
  const int substeps = regions.schedule(kPrimaryRegion).substeps;
  std::array<double, 3> first_push{};
  if (state_ == State::kEngaged && (!proxy_ || proxy_->inward_normal() != inward_)) {
    // The regions went to another face under an engaged tool (followed to a node whose normal is
    // not the touched face's): nothing pushes it there; it waits for regions on its own face.
    state_ = State::kWaiting;
    out_of_region_ = false;
    if (const auto node = NodeInsideFace(OnTouchedFace(tool_))) wanted_ = node;
  }
  if (state_ == State::kWaiting) TryEngage(bound_centre_, now_ns);
  // A release is over once its push has faded.
  if (state_ == State::kReleasing && ReleaseScale(now_ns) <= 0) {
    state_ = State::kAwaitLiftOff;
    pushed_n_ = {};
  }
  if (RampScale(now_ns) >= 1.0) ramp_start_ns_ = -1;
  if (catch_up_ns_ >= 0 && now_ns - catch_up_ns_ >= catch_up_duration_ns_) catch_up_ns_ = -1;
  for (int q = 1; q <= substeps; ++q) {
    // The substeps move the tool from the last period's tip to this one's in equal parts; after a
    // pause, less what it moved while the regions stood still, given back over the catch-up.
    SubstepPush step(*this, now_ns);
    const double lag = CatchUpLag(now_ns);
    for (int c = 0; c < 3; ++c) {
      step.tool_m[c] = last_tool_[c] + (tool_[c] - last_tool_[c]) * q / substeps -
                       lag * catch_up_tool_m_[c];
    }
    regions.StepPrimaryPushed(step);
    if (q == 1) first_push = step.push_n;
    // Where the regions last had the tool, lag included: a pause before the catch-up is over
    // owes what was still to be given back too.
    stepped_tool_ = step.tool_m;
  }
  last_push_ = first_push;
  AfterPeriod();
  return first_push;
}

void SlidingContact::SubstepPush::Load(const Eigen::VectorXd& predicted,
                                       std::span<const double> compliance,
                                       std::span<double> load) noexcept {
  std::fill(load.begin(), load.end(), 0.0);
  SlidingContact& c = contact_;
  if (c.state_ == State::kReleasing) {
    // The last push fading out where it pushed, on the regions it pushed; on regions bound since
    // (a move's pause under the release, through which HapticLoop rendered the fade too) the
    // user's fade goes on, the object free meanwhile: ending it there would drop what is left of
    // it at once.
    push_n = c.ReleasingPush(now_ns_);
    if (c.proxy_ && c.bindings_ == c.pushed_binding_) c.proxy_->SpreadLoads(push_n, load);
    return;
  }
  if (c.state_ != State::kEngaged || !c.proxy_) return;
  const ProxyContact::Result touch = c.proxy_->Update(tool_m, predicted, compliance, load);
  if (touch.left_surface) {
    // Off the face's rim: let go, the push fading out; a new touch only after the tip has left
    // the object, or risen into a wall, through it (TouchTheWall).
    c.Release(now_ns_);
    c.wall_within_m_ = 2 * touch.into_wall_m;
    c.wall_inward_ = touch.into_wall_inward;
    if (c.state_ == State::kReleasing) {
      push_n = c.pushed_n_;
      c.proxy_->SpreadLoads(push_n, load);
    }
    return;
  } else if (touch.left_region) {
    c.out_of_region_ = true;  // nothing pushed until the regions are under it again
  } else if (c.out_of_region_ && touch.in_contact) {
    c.out_of_region_ = false;  // back in a primary: its push ramps in again
    c.ramp_start_ns_ = now_ns_;
  }
  if (c.state_ == State::kEngaged && touch.in_contact) {
    push_n = c.Rendered(touch, now_ns_);
    c.proxy_->SpreadLoads(push_n, load);
    c.pushed_n_ = push_n;
    c.pushed_binding_ = c.bindings_;
  } else {
    c.pushed_n_ = {};
    // Nothing pushed (Update left the loads zero), nothing felt: a blend from a held push would
    // be a force the object never gets back. The tool's lag goes with it, so a touch again in
    // the next substeps would start at the tool's full depth: it ramps in instead.
    if (c.catch_up_ns_ >= 0) c.ramp_start_ns_ = now_ns_;
    c.catch_up_ns_ = -1;
  }
}

void SlidingContact::CatchUp(std::int64_t now_ns, std::int64_t paused_ns,
                             bool hold_expired) noexcept {
  if (state_ != State::kEngaged) return;
  if (hold_expired) {  // the push was released meanwhile: it ramps in again from zero
    ramp_start_ns_ = now_ns;
    catch_up_ns_ = -1;
    return;
  }
  catch_up_ns_ = now_ns;
  catch_up_anchored_ = false;
  held_push_ = last_push_;
  // The regions stood still where the last period before the pause left them, the tool did not:
  // the proxy follows the tool less that motion, given back over the catch-up, so the tissue
  // takes up where it stopped. (Lifting out further than the spring was compressed, the tool
  // was off the tissue the pause held: the push went to nothing, and the tissue sprang back up
  // into the tool in the next periods — 0.12 N → 0 → 0.06 N on the palpation phantom.)
  for (int c = 0; c < 3; ++c) catch_up_tool_m_[c] = tool_[c] - stepped_tool_[c];
  // Twice as long as the pause (what the tool did meanwhile comes back at half its pace), at most
  // kCatchUp_ns; none after no pause at all.
  catch_up_duration_ns_ = std::min(kCatchUp_ns, 2 * paused_ns);
}

void SlidingContact::AfterPeriod() noexcept {
  following_ = false;
  if (state_ != State::kEngaged || !proxy_) return;
  std::optional<LatticeIndex> next =
      ProxyWantsPrimaryAt(*proxy_, bound_centre_, object_.spacing_m());
  // Slid out of the primary before it followed: the node inside the face nearest the proxy (never a
  // rim node, whose normal is not the face's).
  if (!next && out_of_region_) {
    next = NodeInsideFace(OnTouchedFace(proxy_->proxy_rest_m()));
  }
  if (next && *next != bound_centre_) {
    wanted_ = *next;
    following_ = true;
  }
}

void SlidingContact::Release(std::int64_t now_ns) noexcept {
  // Only what the primary thread owns: Update calls this while Bind may be writing proxy_.
  following_ = out_of_region_ = false;
  ramp_start_ns_ = catch_up_ns_ = -1;
  if (!Pushes(pushed_n_)) {
    state_ = State::kAwaitLiftOff;
    return;
  }
  state_ = State::kReleasing;
  release_start_ns_ = now_ns;
  // A smoothstep over T sheds at most 1.5·F/T a unit of time: T long enough to keep that under
  // kReleaseRate_n_per_ns (a wall's push, not held to friction, is as deep as the tool is past
  // the wall: 1.96 N at 2 cm stepped by 0.164 N a period over 20 ms).
  // At most kMaxRelease_ns: a pause of the regions holds a fade no longer (HapticLoop).
  const double push = std::hypot(pushed_n_[0], pushed_n_[1], pushed_n_[2]);
  const double fade_ns = std::isfinite(push) ? 1.5 * push / kReleaseRate_n_per_ns : 0.0;
  release_ns_ = static_cast<std::int64_t>(
      std::clamp(fade_ns, static_cast<double>(kRelease_ns), static_cast<double>(kMaxRelease_ns)));
}

std::array<double, 3> SlidingContact::ReleasingPush(std::int64_t now_ns) const noexcept {
  if (state_ != State::kReleasing) return {};
  const double scale = ReleaseScale(now_ns);
  return {scale * pushed_n_[0], scale * pushed_n_[1], scale * pushed_n_[2]};
}

bool SlidingContact::PressedIn(const std::array<double, 3>& tip_m) const noexcept {
  // The tip's depth past the touched face's plane, as ContactTracker::SlipsOff tests it: a tip
  // lifted straight out is not (the tissue pressed in behind the plane, its spring let go before
  // the tip left).
  double depth = 0;
  for (int c = 0; c < 3; ++c) {
    if (inward_[c] != 0) depth = (tip_m[c] - face_m_) * inward_[c];
  }
  return depth > ContactTracker::kDeepTouchDown_m;
}

double SlidingContact::ReleaseScale(std::int64_t now_ns) const noexcept {
  const double tau = static_cast<double>(now_ns - release_start_ns_) / release_ns_;
  return tau >= 1 ? 0.0 : 1.0 - Smoothstep(std::max(0.0, tau));
}

void SlidingContact::RestartFromRest() noexcept {
  if (state_ != State::kFree) state_ = State::kAwaitLiftOff;
  wall_within_m_ = 0;
  following_ = out_of_region_ = false;
  ramp_start_ns_ = catch_up_ns_ = -1;
}

void SlidingContact::RestartKeepingContact() noexcept {
  if (state_ == State::kReleasing) state_ = State::kAwaitLiftOff;  // what it pushed is gone
  wall_within_m_ = 0;
  if (state_ == State::kEngaged || state_ == State::kWaiting) {
    // The motion the proxy pressed into is gone: it touches again where the tool is, once regions
    // on its face can push there (TryEngage), its force ramped in. It wants the node under the
    // tip, not one it asked to follow to: that may have been refused.
    state_ = State::kWaiting;
    if (const auto node = NodeInsideFace(OnTouchedFace(tool_))) wanted_ = node;
    following_ = out_of_region_ = false;
    catch_up_ns_ = -1;
  }
}

}  // namespace hapticsim
