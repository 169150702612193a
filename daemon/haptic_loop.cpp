#include "daemon/haptic_loop.hpp"

#include <pthread.h>
#include <sched.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <string>

#include "core/error.hpp"
#include "rt/monotonic_clock.hpp"

namespace hapticsim {
namespace {

// Named threads show up as such in top -H, ps -L, perf and gdb (15 characters at most).
void NameThisThread(const std::string& name) {
  pthread_setname_np(pthread_self(), name.substr(0, 15).c_str());
}

}  // namespace

std::int64_t HapticLoop::NowNs() noexcept { return MonotonicNowNs(); }

HapticLoop::HapticLoop(const Scene& scene, const Options& options)
    : scene_(scene),
      options_(options),
      object_(ContactObject::Of(scene)),
      contact_(object_, options.engage_ramp_s),
      guard_(options.port, 1e-3) {
  if (UsesProxyContact(scene)) sliding_.emplace(object_, scene.contact, options.engage_ramp_s);
  auto regions = std::make_unique<AsyncRegions>(scene);
  std::optional<SlidingContact::Binding> binding;
  if (sliding_) binding = sliding_->Prepare(*regions);
  Install(scene, std::move(regions), std::move(binding));
  guard_ =
      PortGuard(options.port, primary_period_ns_ * 1e-9,
                options.port_guard_off ? PortGuard::Mode::kOffForTests : PortGuard::Mode::kGuarded);
  tip_ =
      InputResampler(primary_period_ns_ * 1e-9, kMaxPredictedPeriods * primary_period_ns_ * 1e-9);
}

HapticLoop::~HapticLoop() { Stop(); }

std::array<double, 3> HapticLoop::StepPrimaryPeriod(
    const std::array<double, 3>& contact_m) noexcept {
  // The device gives one position per period: the substeps go there in equal parts, from where
  // the last period left the contact (holding it for every substep would move the contact node a
  // period's way in one substep: a drag of 4m/dt on its mass m).
  const int substeps = regions_->schedule(kPrimaryRegion).substeps;
  const std::array<double, 3> from = regions_->primary_contact_m();
  std::array<double, 3> reaction{};
  for (int q = 1; q <= substeps; ++q) {
    std::array<double, 3> to;
    for (int c = 0; c < 3; ++c) {  // the last substep exactly where the device put the tip
      to[c] = q == substeps ? contact_m[c] : from[c] + (contact_m[c] - from[c]) * q / substeps;
    }
    const std::array<double, 3> r = regions_->StepPrimary(to);
    if (q == 1) reaction = r;
  }
  return reaction;
}

std::optional<LatticeIndex> HapticLoop::wanted_contact_node() const {
  const std::int64_t code = counters_.wanted_node_code.value();
  if (code < 0) return std::nullopt;
  return object_.Decode(code);
}

void HapticLoop::SetErrorState(double error_percent, std::int32_t flags) noexcept {
  error_percent_.Set(error_percent);
  error_flags_.Set(flags);
}

void HapticLoop::OfferInput(const DeviceSample& sample) noexcept { inputs_.Offer(sample); }

std::int64_t HapticLoop::primary_alive_ns() const {
  return std::max(monitors_[kPrimaryRegion]->last_done_ns(), counters_.alive_ns.value());
}

void HapticLoop::WaitForInput() noexcept {
  // Not at all after an input offered since the period took its inputs, a reconfiguration or a
  // stop.
  inputs_.WaitForArrival(kIdleWait_s,
                         [this] { return stop_.load() || handover_.pause_requested(); });
  counters_.alive_ns.Set(NowNs());
}

void HapticLoop::PrimaryPeriod(std::int64_t release_ns, std::int64_t now_ns) noexcept {
  inputs_.Drain([this](const DeviceSample& sample) { TakeInput(sample); });
  const bool have = last_input_.seq >= 0;
  const bool stale =
      !have || static_cast<double>(now_ns - last_input_.received_ns) > options_.stale_after_s * 1e9;
  std::int32_t flags = error_flags_.value();
  if (stale) {
    flags |= force_flags::kInputStale;
    if (have) counters_.stale_periods.Add();
  }
  if (last_input_.latest_rejected) flags |= force_flags::kInputRejected;

  const bool usable = RegionsAreOurs(release_ns);
  const bool holding =
      !usable && holding_ && held_periods_++ * primary_period_ns_ < kMaxHold_s * 1e9;
  if (usable) {
    holding_ = false;
    ApplyRestart(release_ns);
  } else {
    counters_.paused_periods.Add();
    flags |= force_flags::kReconfiguring;
  }

  // Stale input holds the contact where it was; fresh input moves it. Both on the release grid,
  // not on when this thread woke: a period woken late must not hurry the tip or the engage ramp
  // (the driven node's inertia turns an uneven step into a force spike).
  if (usable) held_centre_ = centre_;
  const std::optional<LatticeIndex> centre =
      usable || holding ? std::optional<LatticeIndex>(held_centre_) : std::nullopt;
  const ContactTracker::Contact contact = TrackContact(have && !stale, release_ns, centre, usable);
  const bool in_contact = contact.engaged && (usable || holding);
  if (usable) engaged_ = in_contact;
  if (!contact.engaged) holding_ = false;  // lifted off while held: a new touch is not held
  if (contact.waiting) flags |= force_flags::kReconfiguring;
  PublishContactRequest(contact);
  const std::array<double, 3> reaction =
      PeriodReaction(usable, holding, contact, release_ns, &flags);
  counters_.idle.Set(usable && sleep_state_ == kAsleep && stale);
  const bool render = in_contact && !(stale && options_.zero_force_when_stale);
  const std::array<double, 3> simulated_n{-reaction[0], -reaction[1], -reaction[2]};
  const PortGuard::Output sent = GuardPeriod(now_ns, simulated_n, render, contact, have, &flags);
  if (in_contact) {
    flags |= force_flags::kInContact;
    counters_.last_contact_ns.Set(now_ns);
  }
  counters_.in_contact.Set(in_contact);
  PublishPeriod(now_ns, sent.force_n, simulated_n, flags);
}

ContactTracker::Contact HapticLoop::TrackContact(bool fresh, std::int64_t release_ns,
                                                 const std::optional<LatticeIndex>& centre,
                                                 bool usable) noexcept {
  if (sliding_) {
    // Not while the regions are held for a reconfiguration: the supervisor rebinds the proxy then.
    const std::optional<LatticeIndex> ours = usable ? centre : std::nullopt;
    return fresh ? sliding_->Update(tip_.TipAt(release_ns), release_ns, ours)
                 : sliding_->Hold(release_ns, ours);
  }
  return fresh ? contact_.Update(tip_.TipAt(release_ns), release_ns, centre)
               : contact_.Hold(release_ns, centre);
}

void HapticLoop::PublishContactRequest(const ContactTracker::Contact& contact) noexcept {
  counters_.contact_waiting.Set(contact.waiting);
  counters_.contact_following.Set(contact.following);
  const std::optional<LatticeIndex> wanted =
      sliding_ ? sliding_->wanted_node() : contact_.wanted_node();
  counters_.wanted_node_code.Set(wanted ? object_.Code(*wanted) : -1);
}

std::array<double, 3> HapticLoop::PeriodReaction(bool usable, bool holding,
                                                 const ContactTracker::Contact& contact,
                                                 std::int64_t release_ns,
                                                 std::int32_t* flags) noexcept {
  watched_this_period_ = false;  // until WatchEnergyBalance runs on these regions below
  if (!usable) {
    // Paused under a push let go, its fade goes on (SlidingContact::ReleasingPush), not held.
    if (holding && sliding_ && sliding_->releasing()) return sliding_->ReleasingPush(release_ns);
    return holding ? held_reaction_ : std::array<double, 3>{};
  }
  std::array<double, 3> reaction{};
  // Asleep, the regions are exactly at rest at time 0: a touch steps on from there in this very
  // period, with the secondaries restarted on this release.
  if (sleep_state_ == kAsleep && contact.engaged) WakeSecondaries(release_ns);
  if (sleep_state_ != kAsleep) {
    reaction = sliding_ ? sliding_->StepPeriod(*regions_, release_ns)
                        : StepPrimaryPeriod(contact.displacement_m);
    // Only here: while paused for a reconfiguration the regions are not the primary's to read.
    if (regions_->primary_boundary_age_s() > kStaleBoundary_s) {
      *flags |= force_flags::kBoundaryStale;
    }
    WatchEnergyBalance();
    if (options_.sleep_at_rest) WatchForRest(contact.engaged);
  }
  held_reaction_ = reaction;
  return reaction;
}

PortGuard::Output HapticLoop::GuardPeriod(std::int64_t now_ns,
                                          const std::array<double, 3>& simulated_n, bool render,
                                          const ContactTracker::Contact& contact, bool have,
                                          std::int32_t* flags) noexcept {
  PortGuard::Input port;
  port.now_ns = now_ns;
  port.simulated_n = simulated_n;
  port.render = render;
  port.engaged = contact.engaged;
  // The port's motion: in contact, the contact point's path — the positions received, resampled
  // on this period, and during an engagement ramp the ramp's, so that what the ramp stores in the
  // tissue counts as absorbed (else a tissue engaged at depth could never push back).
  port.position_m = contact.engaged ? contact.point_m : last_input_.position_m;
  port.have_position = have;
  port.inward_normal = contact.inward_normal;
  const PortGuard::Output sent = guard_.Period(port);
  UpdateFaultState(sent);
  if (sent.limited) {
    *flags |= force_flags::kForceLimited;
    counters_.limited_periods.Add();
  }
  if (sent.dissipating) {
    *flags |= force_flags::kPortDissipating;
    counters_.dissipating_periods.Add();
  }
  if (sent.latched) *flags |= force_flags::kFaultLatched;
  return sent;
}

bool HapticLoop::RegionsAreOurs(std::int64_t release_ns) noexcept {
  bool pause_began = false;
  const RegionHandover::Period period = handover_.Check(release_ns, &pause_began);
  if (pause_began) {
    // Paused to carry the motion to new regions, a contact engaged until now keeps its node and
    // the force it had, until they take over (at most kMaxHold_s); any other contact gets none.
    holding_ = handover_.hold_force() && engaged_;
    held_periods_ = 0;
  }
  return period == RegionHandover::Period::kOurs;
}

void HapticLoop::ApplyRestart(std::int64_t release_ns) noexcept {
  switch (handover_.TakeRestart()) {
    case RegionRestart::kFromRest:
      if (sliding_) {
        sliding_->RestartFromRest();
      } else {
        contact_.RestartFromRest();
      }
      restarted_since_fault_ = guard_.latched();
      guard_.Reengage();
      break;
    case RegionRestart::kKeepingContact:
      if (sliding_) {
        sliding_->RestartKeepingContact();
      } else {
        contact_.RestartKeepingContact();
      }
      guard_.Reengage();
      break;
    case RegionRestart::kCarryingMotion:
      // The new regions hold the contact where the last period before the pause left it (a
      // sliding tool's proxy goes on where it was, Install bound it to them, and its push comes
      // back from the one held: SlidingContact::CatchUp).
      if (sliding_) {
        // The pause held the push for at most kMaxHold_s (PrimaryPeriod), then released it.
        const double paused_ns = static_cast<double>(held_periods_) * primary_period_ns_;
        const bool expired =
            held_periods_ > 0 &&
            static_cast<double>(held_periods_ - 1) * primary_period_ns_ >= kMaxHold_s * 1e9;
        sliding_->CatchUp(release_ns, static_cast<std::int64_t>(paused_ns), expired);
      } else {
        contact_.CatchUpFrom(regions_->primary_contact_m(),
                             release_ns - static_cast<std::int64_t>(primary_period_ns_));
      }
      break;
    case RegionRestart::kNone:
      return;
  }
  RestartEnergyWatch();  // the balance starts afresh with the new regions
}

void HapticLoop::RestartEnergyWatch() noexcept {
  balance_peak_stored_j_ = 0;
  runaway_seen_ = false;
  runaway_periods_ = 0;
  over_watch_line_ = 0;
}

void HapticLoop::PublishPeriod(std::int64_t now_ns, const std::array<double, 3>& force_n,
                               const std::array<double, 3>& raw_force_n,
                               std::int32_t flags) noexcept {
  ForceRecord out;
  out.period = periods_run_++;
  out.seq = last_input_.seq;
  out.first_seq = first_taken_seq_ >= 0 && taken_in_sequence_ ? first_taken_seq_ : out.seq;
  first_taken_seq_ = -1;
  taken_in_sequence_ = true;
  out.utime_us = now_ns / 1000;
  out.error_percent = error_percent_.value();
  out.force_n = force_n;
  out.flags = flags;
  forces_.Push(out);
  BlackBoxRecord box;
  box.time_ns = now_ns;
  box.seq = out.seq;
  box.position_m = last_input_.position_m;
  box.force_n = out.force_n;
  box.raw_force_n = raw_force_n;
  box.port_energy_j = guard_.port_energy_j();
  box.error_percent = out.error_percent;
  box.flags = flags;
  black_box_.Push(box);
}

void HapticLoop::TakeInput(const DeviceSample& sample) noexcept {
  // Arrived before the newest taken (still in the ring after an overflow took the newest): gone.
  if (sample.received_ns < last_input_.received_ns) return;
  if (sample.seq != last_input_.seq) {
    tip_.Add(sample.seq, sample.received_ns, sample.position_m);
    if (first_taken_seq_ < 0) {
      first_taken_seq_ = sample.seq;
    } else if (sample.seq != last_input_.seq + 1) {
      taken_in_sequence_ = false;  // one lost between, or a restarted driver
    }
  }
  last_input_ = sample;  // the same seq again: the rejected-input flag may have changed
}

void HapticLoop::UpdateFaultState(const PortGuard::Output& sent) noexcept {
  if (sent.new_fault != PortGuard::Fault::kNone) {
    // A simulated force no tissue gives (or none at all), in a period these regions stepped,
    // while their state has been above the runaway watch's line in at least kFaultRunawayPeriods
    // of the watch's last kRunawayPeriods periods: that is the runaway the watch would count
    // some periods later (its ratio swings across the line from period to period as it grows).
    // Counted now, before the fault, so that the supervisor takes the regions off this
    // configuration instead of restarting it from rest — and the watch's count with it — where it
    // ran away. One period above the line is a prescribed jump of the contact node (see
    // AsyncRegions::kRunawayPeriods), not a runaway.
    const bool diverged = sent.new_fault == PortGuard::Fault::kDivergence ||
                          sent.new_fault == PortGuard::Fault::kNonFinite;
    const int recent =
        std::popcount(over_watch_line_ & ((1u << AsyncRegions::kRunawayPeriods) - 1));
    if (diverged && watched_this_period_ && recent >= kFaultRunawayPeriods) PublishRunaway();
    counters_.last_fault.Set(static_cast<int>(sent.new_fault));
    counters_.fault_latched.Set(true);
    restarted_since_fault_ = false;
    counters_.force_faults.Add();  // the supervisor restarts the regions
  }
  // Re-armed only from rest with the tool out of the object: the next touch engages from zero.
  const bool outside = sliding_ ? sliding_->outside() : contact_.outside();
  if (guard_.latched() && restarted_since_fault_ && outside) {
    guard_.Rearm();
    restarted_since_fault_ = false;
    counters_.fault_latched.Set(false);
    counters_.rearms.Add();
  }
  counters_.port_dissipated_j.Set(guard_.dissipated_j());
}

void HapticLoop::WatchEnergyBalance() noexcept {
  const AsyncRegions::PublishedBalanceView balance = regions_->PublishedBalance();
  balance_peak_stored_j_ = std::max(balance_peak_stored_j_, balance.stored_j);
  counters_.interface_backlog_j.Set(balance.backlog_j);
  counters_.interface_backlog_max_j.RaiseTo(balance.backlog_j);
  const double scale = std::max(balance_peak_stored_j_, regions_->port_floor_j());
  // Above the reserve the primary leaves to the shells by design, as EnergyAboveBound counts.
  if (balance.backlog_j - balance.primary_reserve_j > kBacklogTolerance * scale) {
    counters_.balance_violations.Add();
  }
  // Once per set of regions: the supervisor takes them off this configuration (release: the
  // regions it reads with the count are the ones that ran away).
  const bool held = regions_->RunawayHeld(balance, &runaway_periods_);
  watched_this_period_ = true;
  over_watch_line_ = (over_watch_line_ << 1) | (runaway_periods_ > 0 ? 1u : 0u);
  if (runaway_periods_ > 0) {
    watched_ = {balance.state_energy_j, std::max(balance.allowed_j, regions_->port_floor_j())};
  }
  if (held) PublishRunaway();
}

void HapticLoop::PublishRunaway() noexcept {
  if (runaway_seen_) return;
  runaway_seen_ = true;
  counters_.PublishRunaway(watched_);
}

void HapticLoop::PrimaryThread(std::int64_t origin_ns) {
  NameThisThread("hsim-primary");
  DeadlineMonitor& monitor = *monitors_[kPrimaryRegion];  // never replaced
  for (std::int64_t k = 0; !stop_.load(std::memory_order_acquire); ++k) {
    const std::int64_t release =
        origin_ns + std::llround(static_cast<double>(k) * primary_period_ns_);
    SleepUntilMonotonicNs(release);
    const std::int64_t woke = NowNs();
    PrimaryPeriod(release, woke);
    monitor.Record(release, woke, NowNs());
    if (counters_.idle.value()) {
      // Asleep and no device: nothing to answer until an input arrives. Then back on the release
      // grid at its next release (the periods waited through had nothing to answer).
      WaitForInput();
      const double now_periods = static_cast<double>(NowNs() - origin_ns) / primary_period_ns_;
      k = std::max(k, static_cast<std::int64_t>(std::ceil(now_periods)) - 1);
    }
  }
}

void HapticLoop::SecondaryThread(RegionIndex region, std::int64_t origin_ns) {
  NameThisThread("hsim-region" + std::to_string(region));
  DeadlineMonitor& monitor = *monitors_[region];
  const int substeps = regions_->schedule(region).substeps;
  const double period_ns = 1e9 / regions_->schedule(region).rate_hz;
  std::int64_t woken_ns = 0;  // when it last came out of parking
  while (!stop_secondaries_.load(std::memory_order_acquire)) {
    const std::uint32_t generation = parking_.generation();
    if (!SecondaryMayStep(region)) {
      const std::int64_t wake_origin =
          parking_.WaitForWake(generation, stop_secondaries_, kIdleWait_s);
      if (wake_origin >= 0) origin_ns = wake_origin;  // the regions restart from rest there
      woken_ns = NowNs();
      continue;
    }
    // Woken, a region meant to run ahead of the primary (lead_ns_) starts behind it (and behind
    // by more if the primary woke it late): its steps until it is ahead again count as released
    // when it woke, so they run at once and are not misses — unless this thread is held up after
    // waking, which counts from then and skips as below.
    const std::int64_t release = std::max(
        woken_ns, origin_ns + static_cast<std::int64_t>(regions_->state_ticks(region) * tick_ns_) -
                      lead_ns_[region]);
    // Asked to stop (new regions replace these), it does not sleep on to a release far ahead.
    if (!SleepUntilMonotonicNsOrStop(release, stop_secondaries_)) break;
    const std::int64_t woke = NowNs();
    // Stalled (preempted, a debugger, a page-fault storm): hold the state over the missed periods
    // and carry on from the present, rather than stepping them late against the inner region's
    // present state (see AsyncRegions::SkipRegion).
    const auto missed = static_cast<std::int64_t>(static_cast<double>(woke - release) / period_ns);
    if (missed > kSkipAfterLatePeriods) {
      regions_->SkipRegion(region, missed * substeps);
      counters_.skipped_periods[region].Add(missed);
      counters_.stalls[region].Add();
    }
    for (int q = 0; q < substeps; ++q) regions_->StepRegion(region);
    monitor.Record(release, woke, NowNs());
  }
}

void HapticLoop::StartSecondaries(std::int64_t origin_ns) {
  stop_secondaries_ = false;
  for (int a = 1; a < regions_->num_regions(); ++a) {
    secondary_threads_.emplace_back([this, a, origin_ns] { SecondaryThread(a, origin_ns); });
    ApplyRealtimeSettings(secondary_threads_.back());
  }
}

void HapticLoop::StopSecondaries() {
  stop_secondaries_ = true;
  parking_.WakeAll();  // parked ones come round and see the stop
  for (std::thread& thread : secondary_threads_) {
    if (thread.joinable()) thread.join();
  }
  secondary_threads_.clear();
}

std::string HapticLoop::Start() {
  if (running_) return "";
  regions_->Reset();
  ForgetSleep();
  stop_ = false;
  const std::int64_t origin_ns = NowNs() + 5'000'000 + lead_ns_.back();
  origin_ns_ = origin_ns;
  handover_.Reset(RegionRestart::kFromRest, origin_ns);
  primary_thread_ = std::thread([this, origin_ns] { PrimaryThread(origin_ns); });
  std::string refused = ApplyRealtimeSettings(primary_thread_);
  StartSecondaries(origin_ns);
  running_ = true;
  return refused;
}

std::string HapticLoop::ApplyRealtimeSettings(std::thread& thread) const {
  std::string refused;
  const pthread_t handle = thread.native_handle();
  if (options_.fifo_priority > 0) {
    sched_param param{};
    param.sched_priority = options_.fifo_priority;
    const int error = pthread_setschedparam(handle, SCHED_FIFO, &param);
    if (error != 0) {
      refused += "SCHED_FIFO priority " + std::to_string(options_.fifo_priority) + " refused (" +
                 std::strerror(error) + "; needs CAP_SYS_NICE or LimitRTPRIO); ";
    }
  }
  if (!options_.cpus.empty()) {
    cpu_set_t set;
    CPU_ZERO(&set);
    for (int cpu : options_.cpus) CPU_SET(cpu, &set);
    const int error = pthread_setaffinity_np(handle, sizeof set, &set);
    if (error != 0) refused += std::string("CPU affinity refused (") + std::strerror(error) + "); ";
  }
  return refused;
}

void HapticLoop::Stop() {
  stop_ = true;
  inputs_.Nudge();  // an idle primary waiting for input comes round now
  if (primary_thread_.joinable()) primary_thread_.join();
  StopSecondaries();
  running_ = false;
}

}  // namespace hapticsim
