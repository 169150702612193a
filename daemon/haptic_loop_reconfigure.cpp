// Replacing the regions while hapticsimd's loop runs (HapticLoop::Reconfigure): the hand-over
// between the supervisor, which builds and installs the new regions, and the primary thread,
// which answers every period meanwhile.
#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include "core/error.hpp"
#include "core/regions/release_lead.hpp"
#include "daemon/haptic_loop.hpp"
#include "rt/monotonic_clock.hpp"

namespace hapticsim {

void HapticLoop::Install(const Scene& scene, std::unique_ptr<AsyncRegions> regions,
                         std::optional<SlidingContact::Binding> binding) {
  {
    const std::lock_guard<std::mutex> lock(surface_mutex_);
    scene_ = scene;
    regions_ = std::move(regions);
    ++installs_;
  }
  centre_ = regions_->partition().contact_node();
  // The primary leaves the regions alone meanwhile, and the sliding tool's proxy with them.
  if (sliding_ && binding) sliding_->Bind(std::move(*binding));
  const int count = regions_->num_regions();
  tick_ns_ = 1e9 / static_cast<double>(regions_->ticks_per_second());
  auto nominal_ns = [&](int a) {
    return static_cast<double>(regions_->period_ticks(a) * regions_->schedule(a).substeps) *
           tick_ns_;
  };
  if (monitors_.empty()) {  // the primary's period is fixed for the loop's life
    primary_period_ns_ = nominal_ns(kPrimaryRegion);
    monitors_.push_back(std::make_unique<DeadlineMonitor>(primary_period_ns_ * 1e-9));
  }
  std::vector<std::unique_ptr<DeadlineMonitor>> replaced(
      std::make_move_iterator(monitors_.begin() + 1), std::make_move_iterator(monitors_.end()));
  monitors_.resize(1);
  std::vector<double> nominal_period_ns{nominal_ns(kPrimaryRegion)};
  for (int a = 1; a < count; ++a) {
    monitors_.push_back(std::make_unique<DeadlineMonitor>(nominal_ns(a) * 1e-9));
    // The a-th secondary thread's statistics run on across reconfigurations.
    if (a - 1 < static_cast<int>(replaced.size())) monitors_.back()->CarryOver(*replaced[a - 1]);
    nominal_period_ns.push_back(nominal_ns(a));
  }
  // Each outer region released ahead of the inner one, so that its boundary is published before
  // the inner one needs it, and at one rate reads the inner band of its own time (as in
  // RealTimeSchedule).
  lead_ns_ = ReleaseLeadsNs(nominal_period_ns);
}

std::int64_t HapticLoop::NextPrimaryRelease(std::int64_t not_before_ns) const {
  const double periods = std::ceil((not_before_ns - origin_ns_) / primary_period_ns_);
  return origin_ns_ + std::llround(periods * primary_period_ns_);
}

void HapticLoop::Reconfigure(const Scene& scene, Handover handover) {
  const std::int64_t start_ns = NowNs();
  last_replacement_ = ReplacementTimes{};
  auto regions = std::make_unique<AsyncRegions>(scene);  // the slow part, while the loop runs
  // What can throw or allocate of a sliding tool's proxy over them, made before any pause.
  std::optional<SlidingContact::Binding> binding;
  if (sliding_) binding = sliding_->Prepare(*regions);
  const auto& lattice = regions->partition().mesh().options();
  if (PrimaryRateHz(scene) != PrimaryRateHz(scene_) || lattice.lattice_nodes != object_.nodes() ||
      lattice.spacing_m != object_.spacing_m()) {
    throw Error("a reconfiguration cannot change the object's mesh or the primary rate");
  }
  const bool carry = handover == Handover::kCarryMotion;
  if (carry && !sliding_ && regions->partition().contact_node() != centre_) {
    throw Error("the motion can be carried only to regions around the same contact node");
  }
  ++reconfigurations_;
  RegionRestart restart = carry                           ? RegionRestart::kCarryingMotion
                          : handover == Handover::kRampIn ? RegionRestart::kKeepingContact
                                                          : RegionRestart::kFromRest;
  // The last reconfiguration's restart, if the primary has not applied it yet (its regions not yet
  // resumed), is not undone by a milder one: a reset stays a reset (a fault re-arms only after
  // it), a ramp-in stays a ramp-in. (Applied meanwhile, this only makes the restart stricter.)
  const RegionRestart unapplied = handover_.unapplied_restart();
  if (unapplied == RegionRestart::kFromRest ||
      (unapplied == RegionRestart::kKeepingContact && restart == RegionRestart::kCarryingMotion)) {
    restart = unapplied;
  }
  const bool carrying = restart == RegionRestart::kCarryingMotion;
  const std::int64_t built_ns = NowNs();
  last_replacement_.build_s = (built_ns - start_ns) * 1e-9;
  if (!running_.load()) {
    if (carrying) regions->RestoreState(regions_->CaptureState());
    handover_.SetRestartWhileStopped(restart);
    ForgetSleep();
    Install(scene, std::move(regions), std::move(binding));
    last_replacement_.total_s = last_replacement_.build_s;
    return;
  }
  handover_.RequestPause(carrying);
  inputs_.Nudge();  // an idle primary waiting for input comes round now
  // The primary acknowledges at its next release; after that it does not touch the regions.
  const std::int64_t give_up_ns = NowNs() + 1'000'000'000;
  while (!handover_.Acknowledged()) {
    if (NowNs() > give_up_ns) {
      // A primary thread that does not come round in a second is hung: joining it would hang the
      // supervisor too. Leave everything as it is; the watchdog stops getting pings.
      handover_.Withdraw();
      throw Error("the primary thread did not answer within 1 s: regions not replaced");
    }
    SleepUntilMonotonicNs(NowNs() + 100'000);
  }
  const std::int64_t paused_ns = NowNs();
  last_replacement_.pause_s = (paused_ns - built_ns) * 1e-9;
  StopSecondaries();
  last_replacement_.join_s = (NowNs() - paused_ns) * 1e-9;
  // Nothing steps the old regions now: their motion is the new ones' start.
  if (carrying) regions->RestoreState(regions_->CaptureState());
  ForgetSleep();
  Install(scene, std::move(regions), std::move(binding));
  // The new regions start (from rest, or from the carried motion) on the primary's own release
  // grid, late enough for the secondaries to be released ahead of it.
  const std::int64_t resume_at = NextPrimaryRelease(NowNs() + 2'000'000 + lead_ns_.back());
  StartSecondaries(resume_at);
  handover_.Resume(restart, resume_at);
  last_replacement_.total_s = (NowNs() - start_ns) * 1e-9;
}

}  // namespace hapticsim
