#pragma once

#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <functional>
#include <optional>
#include <thread>
#include <vector>

#include "daemon/haptic_loop.hpp"

namespace hapticsim::testing {

/**
 * Plays a device at 1 kHz on absolute sleeps into a running HapticLoop: `tip(n)` for n = 0, 1, …
 * (sent with seq first_seq + n) for at least `periods` periods and until `done()`; returns every
 * force the loop handed over meanwhile (and in the 5 ms after).
 */
inline std::vector<ForceRecord> PlayDevice(
    HapticLoop& loop, int periods, const std::function<std::array<double, 3>(int)>& tip,
    const std::function<bool()>& done = [] { return true; }, std::int64_t first_seq = 0) {
  std::vector<ForceRecord> forces;
  forces.reserve(static_cast<size_t>(periods) + 100);
  auto next = std::chrono::steady_clock::now();
  ForceRecord record;
  for (int n = 0; n < periods || !done(); ++n) {
    loop.OfferInput(DeviceSample{first_seq + n, HapticLoop::NowNs(), tip(n), false});
    while (loop.forces().Pop(&record)) forces.push_back(record);
    next += std::chrono::milliseconds(1);
    std::this_thread::sleep_until(next);
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(5));
  while (loop.forces().Pop(&record)) forces.push_back(record);
  return forces;
}

/**
 * hapticsimd's threads played on this one, for one primary period at `release_ns`: the input
 * (if any) arrives at the release, the secondary regions step in virtual time until they supply
 * the primary's boundary to the period's end (unless one of them may not: parked or paused), as
 * threads released ahead of the primary do (ReleaseLeadsNs), then the primary period runs as if
 * woken on time. Deterministic: no clock is read. With several primary substeps a period, a
 * secondary at the primary's rate reads the band the primary publishes as its next step's
 * (AsyncRegions::ReadInnerLoads), as on threads. (Until 2026-12-06 the secondaries went one
 * substep ahead only, as behind a thread a little late: the organ's walk played so counted 891
 * periods over the energy tolerance, the threads' order none.)
 */
inline void PlayPeriodInVirtualTime(HapticLoop& loop, std::int64_t release_ns,
                                    const std::optional<DeviceSample>& input) {
  if (input) loop.OfferInput(*input);
  auto& regions = const_cast<AsyncRegions&>(loop.regions());
  bool may_step = true;
  for (int r = 1; r < regions.num_regions() && may_step; ++r) may_step &= loop.SecondaryMayStep(r);
  if (may_step) {
    regions.AdvanceSecondariesTo(regions.state_ticks(kPrimaryRegion) +
                                 regions.schedule(kPrimaryRegion).substeps *
                                     regions.period_ticks(kPrimaryRegion));
  }
  loop.PrimaryPeriod(release_ns, release_ns);
}

/**
 * The forces a loop sends, popped after each period, each with its step from the one before it
 * (N; 0 for the first): `each(force_n, step_n)`.
 */
class SentForces {
 public:
  template <typename Each>
  void Pop(HapticLoop& loop, Each each) {
    ForceRecord record;
    while (loop.forces().Pop(&record)) {
      const std::array<double, 3>& f = record.force_n;
      const double step =
          last_ ? std::hypot(f[0] - (*last_)[0], f[1] - (*last_)[1], f[2] - (*last_)[2]) : 0.0;
      last_ = f;
      each(f, step);
    }
  }

 private:
  std::optional<std::array<double, 3>> last_;
};

}  // namespace hapticsim::testing
