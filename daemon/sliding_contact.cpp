#include "daemon/sliding_contact.hpp"

#include <algorithm>
#include <cmath>

#include "core/error.hpp"
#include "core/regions/proxy_following.hpp"

namespace hapticsim {

SlidingContact::SlidingContact(const ContactBox& box, const ContactSettings& settings,
                               double engage_ramp_s)
    : box_(box), settings_(settings), ramp_ns_(static_cast<std::int64_t>(engage_ramp_s * 1e9)) {}

std::optional<LatticeIndex> SlidingContact::NodeInsideFace(
    const ContactBox::Entry& entry) const noexcept {
  LatticeIndex node{};
  const std::array<int, 3>& n = box_.nodes();
  for (int c = 0; c < 3; ++c) {
    const int nearest = static_cast<int>(std::lround(entry.point_m[c] / box_.spacing_m()));
    node[c] = entry.inward_normal[c] != 0 ? (entry.inward_normal[c] > 0 ? 0 : n[c] - 1)
                                          : std::clamp(nearest, 1, std::max(1, n[c] - 2));
  }
  if (!box_.Drivable(node)) return std::nullopt;
  return node;
}

void SlidingContact::Bind(const AsyncRegions& regions) {
  const RegionPartition& partition = regions.partition();
  HAPTICSIM_THROW_UNLESS(partition.proxy_contact(),
                         "internal: a sliding contact on regions built for a driven node");
  const std::array<double, 3> normal = partition.contact_normal();
  bound_centre_ = partition.contact_node();
  int axes = 0;
  for (double c : normal) axes += c != 0 ? 1 : 0;
  if (axes != 1) {  // regions on an edge (hovered over): a touch waits for them on its face
    proxy_.reset();
    loads_.assign(regions.proxy_loaded_dofs().size(), 0.0);
    return;
  }
  if (proxy_ && proxy_->inward_normal() == normal) {
    proxy_->Rebind(partition.PrimaryProxySurface());
  } else {
    proxy_.emplace(partition.PrimaryProxySurface(), bound_centre_, normal, settings_);
  }
  HAPTICSIM_THROW_UNLESS(proxy_->loaded_dofs() == regions.proxy_loaded_dofs(),
                         "internal: the proxy and the primary region load different nodes");
  loads_.assign(proxy_->loaded_dofs().size(), 0.0);
}

SlidingContact::Contact SlidingContact::Update(const std::array<double, 3>& tip_m,
                                               std::int64_t now_ns,
                                               const std::optional<LatticeIndex>& centre) noexcept {
  last_tool_ = state_ == State::kEngaged ? tool_ : tip_m;
  tool_ = tip_m;
  if (!box_.Inside(tip_m)) {
    state_ = State::kFree;
    following_ = out_of_region_ = false;
    std::array<double, 3> nearest = tip_m;  // the point of the box under the hovering tip
    for (int c = 0; c < 3; ++c) nearest[c] = std::clamp(nearest[c], 0.0, box_.extent_m()[c]);
    wanted_ = NodeInsideFace(box_.EntryOf(nearest));
    return {};
  }
  if (state_ == State::kAwaitLiftOff) return {};
  if (state_ == State::kFree) {
    const ContactBox::Entry entry = box_.EntryOf(tip_m);
    inward_ = entry.inward_normal;
    const std::optional<LatticeIndex> node = NodeInsideFace(entry);
    wanted_ = node;
    if (!node) {  // a held face: the support is not rendered (ContactTracker)
      state_ = State::kAwaitLiftOff;
      return {};
    }
    node_ = *node;
    state_ = State::kWaiting;
    TryEngage(centre, now_ns);
    // Engaged at once from outside, the spring starts at the surface: no ramp unless it is deep.
    if (state_ == State::kEngaged && entry.depth_m <= ContactTracker::kDeepTouchDown_m) {
      ramp_start_ns_ = -1;
    }
  } else if (state_ == State::kWaiting) {
    TryEngage(centre, now_ns);
  }
  return Answer();
}

SlidingContact::Contact SlidingContact::Hold(std::int64_t now_ns,
                                             const std::optional<LatticeIndex>& centre) noexcept {
  last_tool_ = tool_;
  if (state_ == State::kWaiting) TryEngage(centre, now_ns);
  return Answer();
}

void SlidingContact::TryEngage(const std::optional<LatticeIndex>& centre,
                               std::int64_t now_ns) noexcept {
  if (!proxy_ || !centre || *centre != node_ || bound_centre_ != node_ ||
      proxy_->inward_normal() != inward_) {
    return;
  }
  proxy_->PlaceUnder(tool_);
  last_tool_ = tool_;
  state_ = State::kEngaged;
  out_of_region_ = following_ = false;
  wanted_ = node_;
  ramp_start_ns_ = now_ns;  // from waiting; a touch engaged at once from outside clears it
}

SlidingContact::Contact SlidingContact::Answer() const noexcept {
  Contact contact;
  if (state_ != State::kEngaged && state_ != State::kWaiting) return contact;
  contact.engaged = state_ == State::kEngaged;
  contact.waiting = state_ == State::kWaiting || out_of_region_;
  contact.following = following_;
  contact.inward_normal = inward_;
  contact.point_m = tool_;  // the port moves with the hand: the spring's end the user holds
  return contact;
}

double SlidingContact::RampScale(std::int64_t now_ns) const noexcept {
  if (ramp_start_ns_ < 0 || ramp_ns_ <= 0) return 1.0;
  const double tau = std::clamp(static_cast<double>(now_ns - ramp_start_ns_) / ramp_ns_, 0.0, 1.0);
  return tau * tau * (3 - 2 * tau);
}

std::array<double, 3> SlidingContact::Rendered(const std::array<double, 3>& spring_n,
                                               std::int64_t now_ns) const noexcept {
  const double scale = RampScale(now_ns);
  std::array<double, 3> push{};
  for (int c = 0; c < 3; ++c) push[c] = scale * spring_n[c];
  if (catch_up_ns_ >= 0 && now_ns - catch_up_ns_ < catch_up_duration_ns_) {
    // A blend of two pushes within the friction cone stays within it (the cone is convex): the
    // user never feels more than μ_s times the normal force, as a fading offset would give.
    const double tau = static_cast<double>(now_ns - catch_up_ns_) / catch_up_duration_ns_;
    const double w = tau * tau * (3 - 2 * tau);
    for (int c = 0; c < 3; ++c) push[c] = held_push_[c] + w * (push[c] - held_push_[c]);
  }
  return push;
}

std::array<double, 3> SlidingContact::StepPeriod(AsyncRegions& regions,
                                                 std::int64_t now_ns) noexcept {
  const int substeps = regions.schedule(kPrimaryRegion).substeps;
  std::array<double, 3> first_push{};
  if (RampScale(now_ns) >= 1.0) ramp_start_ns_ = -1;
  if (catch_up_ns_ >= 0 && now_ns - catch_up_ns_ >= catch_up_duration_ns_) catch_up_ns_ = -1;
  for (int q = 1; q <= substeps; ++q) {
    std::fill(loads_.begin(), loads_.end(), 0.0);
    if (state_ == State::kEngaged && proxy_) {
      // The substeps move the tool from the last period's tip to this one's in equal parts.
      std::array<double, 3> tool;
      for (int c = 0; c < 3; ++c)
        tool[c] = last_tool_[c] + (tool_[c] - last_tool_[c]) * q / substeps;
      const ProxyContact::Result touch = proxy_->Update(tool, regions.primary_state(), loads_);
      if (touch.left_surface) {
        // Off the face's rim: released; a new touch only after the tip has left the object.
        state_ = State::kAwaitLiftOff;
      } else if (touch.left_region) {
        out_of_region_ = true;  // nothing pushed until the regions are under it again
      } else if (out_of_region_ && touch.in_contact) {
        out_of_region_ = false;  // back in a primary: its push ramps in again
        ramp_start_ns_ = now_ns;
      }
      std::array<double, 3> push{};
      if (state_ == State::kEngaged && !touch.left_region) {
        push = Rendered(touch.force_on_object_n, now_ns);
        proxy_->SpreadLoads(push, loads_);
      } else {
        std::fill(loads_.begin(), loads_.end(), 0.0);
      }
      if (q == 1) first_push = push;
    }
    regions.StepPrimaryLoaded(loads_);
  }
  last_push_ = first_push;
  AfterPeriod();
  return first_push;
}

void SlidingContact::CatchUp(std::int64_t now_ns, std::int64_t paused_ns) noexcept {
  if (state_ != State::kEngaged) return;
  catch_up_ns_ = now_ns;
  held_push_ = last_push_;
  // Twice as long as the pause (what the tool did meanwhile comes back at half its pace), at most
  // kCatchUp_ns; none after no pause at all.
  catch_up_duration_ns_ = std::min(kCatchUp_ns, 2 * paused_ns);
}

void SlidingContact::AfterPeriod() noexcept {
  following_ = false;
  if (state_ != State::kEngaged || !proxy_) return;
  std::optional<LatticeIndex> next = ProxyWantsPrimaryAt(*proxy_, bound_centre_, box_.spacing_m());
  if (!next && out_of_region_) next = proxy_->NearestNode();
  if (next && box_.Drivable(*next)) {
    wanted_ = *next;
    following_ = true;
  }
}

void SlidingContact::RestartFromRest() noexcept {
  if (state_ != State::kFree) state_ = State::kAwaitLiftOff;
  following_ = out_of_region_ = false;
  ramp_start_ns_ = catch_up_ns_ = -1;
}

void SlidingContact::RestartKeepingContact() noexcept {
  if (state_ == State::kEngaged || state_ == State::kWaiting) {
    // The motion the proxy pressed into is gone: it touches again where the tool is, once the
    // regions are centred on the node it wants, its force ramped in.
    state_ = State::kWaiting;
    if (wanted_) node_ = *wanted_;
    following_ = out_of_region_ = false;
    catch_up_ns_ = -1;
  }
}

}  // namespace hapticsim
