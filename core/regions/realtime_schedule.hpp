#pragma once

#include <cstdint>
#include <vector>

#include "core/regions/async_regions.hpp"
#include "core/scene/contact_trajectory.hpp"

namespace hapticsim {

/** Deadline statistics of one periodic thread over a run, as its DeadlineMonitor kept them
 *  (rt/deadline_monitor.hpp, the daemon's too): percentiles are its bins' upper edges, 25 % wide. */
struct DeadlineStats {
  double period_s = 0;          ///< wall-clock period, s
  std::int64_t cycles = 0;
  std::int64_t misses = 0;      ///< cycles that started late by more than one period or
                                ///< finished after their next release
  double worst_lateness_s = 0;  ///< worst wake-up lateness after the release time, s
  double execution_p50_s = 0, execution_p99_s = 0, execution_max_s = 0;  ///< step compute time
};

/**
 * Timing faults injected into RealTimeSchedule, on top of whatever the machine does: each is
 * drawn per wake, at the given mean rate per second of wall time, from a random stream per thread
 * (`seed`). The stress test's `--faults` runs every case with them (docs/reliability.md).
 */
struct TimingFaults {
  unsigned seed = 0;
  double secondary_lags_per_s = 0;  ///< a secondary wakes late by 1–max_lag_periods of its periods
  int max_lag_periods = 10;
  double secondary_stalls_per_s = 0;  ///< a secondary stops for up to max_stall_s
  double max_stall_s = 0.3;
  double primary_late_wakes_per_s = 0;  ///< the primary wakes late by 1–max_late_periods periods
  int max_late_periods = 10;
};

/** What the injected faults did in one run. */
struct FaultCounts {
  std::int64_t secondary_lags = 0, secondary_stalls = 0, primary_late_wakes = 0;
  std::int64_t skips = 0;  ///< secondary wakes so late that it held its state (SkipRegion)

  FaultCounts& operator+=(const FaultCounts& more) {
    secondary_lags += more.secondary_lags;
    secondary_stalls += more.secondary_stalls;
    primary_late_wakes += more.primary_late_wakes;
    skips += more.skips;
    return *this;
  }
};

/**
 * Runs AsyncRegions on real clocks: one thread per region, each releasing its steps on absolute
 * CLOCK_MONOTONIC times (clock_nanosleep TIMER_ABSTIME, so lateness never accumulates), sharing
 * the interface only through the regions' lock-free BoundaryChannels. The primary thread never
 * waits for the secondary: it takes whatever Γ snapshots are newest.
 *
 * A secondary woken more than AsyncRegions::kSkipAfterLatePeriods of its periods late holds its
 * state over them and carries on from the present (SkipRegion), as the daemon's threads do.
 *
 * Phases follow the virtual-time schedule: the primary's step over [tᵢ, tᵢ₊₁] is released at
 * wall time tᵢ (its force at tᵢ is out at once); region a's step over [Tⱼ, Tⱼ₊₁] is released
 * lead(a) before Tⱼ (ReleaseLeadsNs, the daemon's rule too), so its Γ at Tⱼ₊₁ is published
 * before the region inwards needs it. At one rate, half a period ahead, it reads the inner state
 * at Tⱼ itself, and its later substeps the inner band the inner region published as its next
 * step's: the virtual-time run's exchange. At different rates, 1.25 periods of region a − 1
 * ahead, the outer region deterministically reads the inner state just before Tⱼ and
 * extrapolates — which is where a threaded run may differ from the virtual-time one (the
 * virtual schedule uses the inner state at Tⱼ itself when Tⱼ falls on the inner region's grid).
 *
 * Threads: Run() starts and joins the two region threads; call it from one thread.
 */
class RealTimeSchedule {
 public:
  /**
   * `wall_seconds_per_second` stretches the wall clock against simulated time: 1 is real time
   * (what `hapticsim simulate --real-time` runs); 3 gives every thread three times its period of
   * wall time, so a shared machine's stalls of a few milliseconds do not make it late. The
   * exchange between the threads — who reads which snapshot — is the same at any stretch.
   */
  explicit RealTimeSchedule(AsyncRegions& regions, double wall_seconds_per_second = 1.0,
                            const TimingFaults& faults = {})
      : regions_(regions), stretch_(wall_seconds_per_second), faults_(faults) {}

  /** Runs the scene's trial in real time and returns the forces like AsyncRegions::RunTrial. */
  TrialResult RunTrial();

  /** Deadline statistics of each region's thread after RunTrial(). */
  const DeadlineStats& stats(RegionIndex region) const { return stats_[region]; }
  /** The faults injected, and the skips they caused, in the last RunTrial(). */
  const FaultCounts& faults() const { return counts_; }

 private:
  AsyncRegions& regions_;
  double stretch_;
  TimingFaults faults_;
  FaultCounts counts_;
  std::vector<DeadlineStats> stats_;
};

}  // namespace hapticsim
