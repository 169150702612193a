#pragma once
// How far ahead of the primary each region's thread is released (RealTimeSchedule, and
// hapticsimd's HapticLoop): the one rule both use, so `hapticsim simulate --threads` measures the
// exchange the daemon runs.

#include <cstdint>
#include <span>
#include <vector>

namespace hapticsim {

/**
 * Region a's step over [T, T + its period] is released lead(a) before T, lead(0) = 0. Each
 * region must publish its Γ before the region inwards needs it, and should read the inner band
 * at T itself, not a period before it. With `nominal_period_ns[a]` the wall time of region a's
 * wake (its substeps in a row):
 *
 * - **Equal periods** (a shell at its inner neighbour's rate): lead(a) = lead(a − 1) + ½ period.
 *   Released half a period before T, the outer region finds the inner one at T (its step to T,
 *   released a whole period before T, takes tens of µs), and publishes Γ at T + period before the
 *   inner one starts on it at T: the exchange the offline trial makes, exactly, when nothing is
 *   late (a later substep of the period reads the band the inner region published as its next
 *   step's: AsyncRegions::ReadInnerLoads). Released 1.25 periods ahead as below it read the inner
 *   band a whole period old, extrapolated: on the cube at primary size 3 and both at 1000 Hz the
 *   threaded force was 5.4 % (relative L2) from the virtual-time one, 0.000–0.3 % now; on the
 *   organ sample (2 substeps each), 1–3 % against 0.013–0.026 %.
 * - **Unequal periods**: lead(a) = lead(a − 1) + 1.25 periods of region a − 1. The outer region's
 *   step then covers several of the inner one's, the first of which the inner region starts at
 *   T: the outer one must be done before, so it reads the inner band a step before T and
 *   extrapolates (0.006 % from the virtual-time run at k 2 r 3 600 Hz, docs/regions.md).
 */
inline std::vector<std::int64_t> ReleaseLeadsNs(std::span<const double> nominal_period_ns) {
  std::vector<std::int64_t> lead(nominal_period_ns.size(), 0);
  for (size_t a = 1; a < nominal_period_ns.size(); ++a) {
    const double inner = nominal_period_ns[a - 1];
    const double periods = nominal_period_ns[a] == inner ? 0.5 : 1.25;
    lead[a] = lead[a - 1] + static_cast<std::int64_t>(periods * inner);
  }
  return lead;
}

}  // namespace hapticsim
