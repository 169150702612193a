#include "daemon/loop_event_log.hpp"

#include <spdlog/fmt/fmt.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <optional>
#include <string>

namespace hapticsim {
namespace {

std::string FaultName(PortGuard::Fault fault, const PortGuardSettings& port) {
  switch (fault) {
    case PortGuard::Fault::kNonFinite:
      return "the simulated force is not finite";
    case PortGuard::Fault::kDivergence:
      return fmt::format("the simulated force exceeded device.fault_force_n = {} N",
                         port.fault_force_n);
    case PortGuard::Fault::kWatchdog:
      return fmt::format(
          "the primary thread was stalled for more than device.watchdog_s = {} s while force "
          "was sent",
          port.watchdog_s);
    default:
      return "unknown";
  }
}

}  // namespace

LoopEventLog::LoopEventLog(HapticLoop& loop, const DaemonConfig& config)
    : loop_(loop),
      config_(config),
      overrun_(HapticLoop::NowNs()),
      held_reconfigurations_(loop.reconfigurations()),
      held_since_ns_(HapticLoop::NowNs()) {
  for (int inner = 0; inner + 1 < loop.regions().num_regions(); ++inner) {
    held_seen_[inner] = loop.regions().held_boundary_steps(inner);  // since the start: not said
  }
  MatchMissLoggers(HapticLoop::NowNs());
}

// One logger per region thread; the count changes when a reconfiguration changes the regions.
void LoopEventLog::MatchMissLoggers(std::int64_t now) {
  if (static_cast<int>(miss_loggers_.size()) == loop_.regions().num_regions()) return;
  Flush(now);
  miss_loggers_.clear();
  for (int r = 0; r < loop_.regions().num_regions(); ++r) {
    miss_loggers_.emplace_back(loop_.regions().partition().RegionName(r),
                               config_.max_log_lines_per_s);
  }
}

void LoopEventLog::Flush(std::int64_t now) {
  for (auto& m : miss_loggers_) m.Flush(now, true);
}

// A secondary region that stalled held its state over the periods it missed (HapticLoop).
void LoopEventLog::ReadStalls() {
  for (int r = 1; r < loop_.regions().num_regions(); ++r) {
    if (loop_.stalls(r) == stalls_seen_[r]) continue;
    spdlog::warn(
        "{} region stalled: it held its state over {} of its periods instead of stepping them "
        "late (the primary held its boundary meanwhile); {} stall(s) so far",
        loop_.regions().partition().RegionName(r), loop_.skipped_periods(r) - skipped_seen_[r],
        loop_.stalls(r));
    stalls_seen_[r] = loop_.stalls(r);
    skipped_seen_[r] = loop_.skipped_periods(r);
  }
}

// A secondary thread that does not run at all: the primary renders on its held boundary.
void LoopEventLog::ReadBoundaryAge() {
  const double boundary_age_s = loop_.regions().primary_boundary_age_s();
  if (boundary_age_s > HapticLoop::kStaleBoundary_s && !boundary_stale_) {
    spdlog::error(
        "the primary's boundary from the secondary region is {:.2f} s old: its thread is not "
        "running; the primary renders on the held boundary (the primary region alone, stable by "
        "its own limit), its forces flagged boundary stale",
        boundary_age_s);
    boundary_stale_ = true;
  } else if (boundary_age_s < HapticLoop::kStaleBoundary_s && boundary_stale_) {
    spdlog::info("the secondary region runs again (its boundary is {:.1f} ms old)",
                 boundary_age_s * 1e3);
    boundary_stale_ = false;
  }
}

// A secondary thread woken late, but by less than its own period, has not missed its deadline;
// yet the region inwards may have needed its Γ before it was published, and stepped on holding
// the newest (at one rate it is released only half a period ahead: ReleaseLeadsNs). Such steps
// are off the exchange the error map measured: said every kHeldBoundaryWindow_ns per link, where
// they were at least kHeldBoundaryShare of the inner region's nominal steps in the window (a
// window with the regions asleep or paused reads low; a quiet machine: about 0.3 % on the organ
// sample; beside two busy threads 11–23 %).
void LoopEventLog::ReadHeldBoundaries(std::int64_t now) {
  const AsyncRegions& regions = loop_.regions();
  if (loop_.reconfigurations() != held_reconfigurations_) {  // new regions count from zero
    held_reconfigurations_ = loop_.reconfigurations();
    held_seen_.fill(0);
  }
  for (int inner = 0; inner + 1 < regions.num_regions(); ++inner) {
    const std::int64_t held = regions.held_boundary_steps(inner);
    held_unsaid_[inner] += std::max<std::int64_t>(0, held - held_seen_[inner]);
    held_seen_[inner] = held;
  }
  if (now - held_since_ns_ < kHeldBoundaryWindow_ns) return;
  const double window_s = (now - held_since_ns_) * 1e-9;
  for (int inner = 0; inner + 1 < regions.num_regions(); ++inner) {
    const double steps =
        window_s * regions.schedule(inner).rate_hz * regions.schedule(inner).substeps;
    const double share = static_cast<double>(held_unsaid_[inner]) / steps;
    if (share < kHeldBoundaryShare) continue;
    spdlog::warn(
        "boundary late: the {} region's Γ came after the {} region needed it in {} of its steps "
        "({:.1f} %) over {:.1f} s, which held the newest Γ (its thread was late for them: by less "
        "than its own period, not a deadline miss of its own)",
        regions.partition().RegionName(inner + 1), regions.partition().RegionName(inner),
        held_unsaid_[inner], 100 * share, window_s);
  }
  held_unsaid_.fill(0);
  held_since_ns_ = now;
}

LoopEventLog::Misses LoopEventLog::ReadDeadlines(std::int64_t now) {
  MatchMissLoggers(now);
  black_box_.Drain(loop_);
  ReadStalls();
  ReadBoundaryAge();
  ReadHeldBoundaries(now);
  Misses misses{};
  for (int r = 0; r < loop_.regions().num_regions(); ++r) {
    DeadlineEvent event;
    while (loop_.monitor(r).PopEvent(&event)) miss_loggers_[r].Add(event), ++misses[r];
    miss_loggers_[r].Flush(now);
  }
  // A primary that overruns again and again is a fault worth the black box.
  if (const std::optional<std::string> burst =
          overrun_.Count(static_cast<int>(misses[kPrimaryRegion]), now)) {
    black_box_.Dump(*burst);
  }
  return misses;
}

bool LoopEventLog::ReadFaults(std::int64_t now) {
  bool latched = false;
  if (loop_.force_faults() > faults_seen_) {
    faults_seen_ = loop_.force_faults();
    if (last_fault_dump_ns_ < 0 || now - last_fault_dump_ns_ > 10'000'000'000) {  // 1 per 10 s
      black_box_.Drain(loop_);
      black_box_.Dump("force fault");
      last_fault_dump_ns_ = now;
    }
    spdlog::error(
        "force fault latched ({}): the force ramps to zero and stays there; the simulation "
        "restarts from rest and the fault re-arms once the tool is out of the object ({} "
        "fault(s) so far)",
        FaultName(loop_.last_fault(), config_.port), faults_seen_);
    latched = true;
  }
  if (loop_.rearms() > rearms_seen_) {
    rearms_seen_ = loop_.rearms();
    spdlog::warn(
        "force fault re-armed: the tool is out of the object and the simulation restarted from "
        "rest; the next touch engages from zero force");
  }
  return latched;
}

}  // namespace hapticsim
