// The order a virtual-time run steps the regions in (SteppingOrder): the substeps' order, or the
// order of hapticsimd's threads, played deterministically on the virtual-time clock.
#include "core/regions/stepping_order.hpp"

#include <limits>
#include <vector>

#include "core/regions/async_regions.hpp"
#include "core/regions/async_regions_region.hpp"
#include "core/regions/release_lead.hpp"

namespace hapticsim {

void AsyncRegions::SetSteppingOrder(SteppingOrder order) {
  stepping_order_ = order;
  // A thread's wake takes its period's substeps in a row: the leads are in those whole periods,
  // on the virtual-time clock's ticks, by the threads' own rule.
  std::vector<double> wake_ticks;
  for (const auto& region : regions_) {
    wake_ticks.push_back(static_cast<double>(region->period_ticks * region->schedule.substeps));
  }
  release_lead_ticks_ = ReleaseLeadsNs(wake_ticks);
}

void AsyncRegions::AdvanceSecondariesForPrimaryStep() noexcept {
  const Region& primary = *regions_[kPrimaryRegion];
  if (stepping_order_ == SteppingOrder::kSubsteps) {
    AdvanceSecondariesTo(primary.state_ticks + primary.period_ticks);
    return;
  }
  // The primary's thread takes its period's substeps at one wake: whatever was released before
  // that wake stepped before all of them, and nothing steps between them.
  const std::int64_t wake = primary.period_ticks * primary.schedule.substeps;
  if (primary.state_ticks % wake == 0) ReleaseSecondariesBy(primary.state_ticks);
}

// Every secondary wake released at or before `ticks` (its period's start less its lead), earliest
// first, each taking its period's substeps in a row, as the threads would have by the primary's
// wake at `ticks`. A tie goes to the outer region, whose lead is the longer. (On threads, a
// secondary released at the primary's own wake starts with it; its steps take tens of µs either
// way, so which reads the other first is a race; here the secondary reads the band first.)
void AsyncRegions::ReleaseSecondariesBy(std::int64_t ticks) noexcept {
  for (;;) {
    RegionIndex next = kPrimaryRegion;
    std::int64_t earliest = std::numeric_limits<std::int64_t>::max();
    for (RegionIndex a = 1; a < num_regions(); ++a) {
      const std::int64_t release = regions_[a]->state_ticks - release_lead_ticks_[a];
      if (release <= ticks && release <= earliest) {
        earliest = release;
        next = a;
      }
    }
    if (next == kPrimaryRegion) return;
    for (int q = 0; q < regions_[next]->schedule.substeps; ++q) StepRegion(next);
  }
}

}  // namespace hapticsim
