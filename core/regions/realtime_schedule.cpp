#include "core/regions/realtime_schedule.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <memory>
#include <random>
#include <thread>

#include "core/error.hpp"
#include "core/regions/release_lead.hpp"
#include "core/trial/trial_recorder.hpp"
#include "rt/deadline_monitor.hpp"
#include "rt/monotonic_clock.hpp"

namespace hapticsim {
namespace {

// What the deadline statistics of a run say, from its thread's monitor (one snapshot: the
// whole run). Percentiles are the monitor's histogram bins' upper edges, as the daemon's are.
DeadlineStats StatsOf(DeadlineMonitor& monitor, double period_s) {
  const DeadlineSnapshot snapshot = monitor.TakeSnapshot();
  DeadlineStats stats;
  stats.period_s = period_s;
  stats.cycles = snapshot.cycles;
  stats.misses = snapshot.misses;
  stats.worst_lateness_s = snapshot.worst_lateness_s;
  stats.execution_p50_s = snapshot.recent_execution_p50_s;
  stats.execution_p99_s = snapshot.recent_execution_p99_s;
  stats.execution_max_s = snapshot.recent_execution_max_s;
  return stats;
}

// One thread's injected faults (TimingFaults): a stream of its own, drawn once per wake.
class FaultDraw {
 public:
  FaultDraw(unsigned seed, int thread) {
    std::seed_seq sequence{seed, static_cast<unsigned>(thread), 0xfa17u};
    rng_.seed(sequence);
  }
  // Whether a fault at `per_s` a second happens at a wake `period_s` after the last.
  bool Happens(double per_s, double period_s) {
    return per_s > 0 && std::uniform_real_distribution<double>(0, 1)(rng_) < per_s * period_s;
  }
  int Periods(int most) { return std::uniform_int_distribution<int>(1, std::max(1, most))(rng_); }
  double Seconds(double most) { return std::uniform_real_distribution<double>(0, most)(rng_); }

 private:
  std::mt19937_64 rng_;
};

}  // namespace

namespace {

// A run's wall-clock grid: simulation ticks to CLOCK_MONOTONIC, each thread's nominal period
// (one wake takes a period's substeps in a row) and how far ahead of the primary it is released.
struct RunGrid {
  double tick_ns = 0;
  std::int64_t origin_ns = 0;  // simulation time 0
  std::int64_t end_ticks = 0;  // the primary's last period's end
  std::vector<std::int64_t> nominal_ticks, lead_ns;
};

RunGrid MakeGrid(const AsyncRegions& regions, double stretch, long steps) {
  RunGrid grid;
  const int count = regions.num_regions();
  grid.tick_ns = stretch * 1e9 / static_cast<double>(regions.ticks_per_second());
  grid.nominal_ticks.assign(static_cast<size_t>(count), 0);
  std::vector<double> nominal_ns(static_cast<size_t>(count), 0.0);
  for (int a = 0; a < count; ++a) {
    grid.nominal_ticks[a] = regions.period_ticks(a) * regions.schedule(a).substeps;
    nominal_ns[a] = static_cast<double>(grid.nominal_ticks[a]) * grid.tick_ns;
  }
  grid.lead_ns = ReleaseLeadsNs(nominal_ns);
  grid.end_ticks = (steps + 1) * grid.nominal_ticks[kPrimaryRegion];
  // Far enough ahead for the outer regions' leads.
  grid.origin_ns = MonotonicNowNs() + 20'000'000 + grid.lead_ns.back();
  return grid;
}

// Secondary region a's thread: a wake per period on its release grid, its faults injected, a
// stall held over as the daemon holds it, until the primary is done.
void RunSecondary(AsyncRegions& regions, const RunGrid& grid, int a, const TimingFaults& faults,
                  DeadlineMonitor& monitor, FaultCounts& faulted,
                  const std::atomic<bool>& primary_done) {
  FaultDraw draw(faults.seed, a);
  const std::int64_t period = grid.nominal_ticks[a];
  const int substeps = regions.schedule(a).substeps;
  const double period_ns = period * grid.tick_ns;
  while (!primary_done.load(std::memory_order_acquire)) {
    const std::int64_t state = regions.state_ticks(a);
    if (state >= grid.end_ticks + period) break;
    const auto release =
        grid.origin_ns + static_cast<std::int64_t>(state * grid.tick_ns) - grid.lead_ns[a];
    SleepUntilMonotonicNs(release);
    std::int64_t held_ns = 0;
    if (draw.Happens(faults.secondary_lags_per_s, period_ns * 1e-9)) {
      held_ns = static_cast<std::int64_t>(draw.Periods(faults.max_lag_periods) * period_ns);
      ++faulted.secondary_lags;
    } else if (draw.Happens(faults.secondary_stalls_per_s, period_ns * 1e-9)) {
      held_ns = static_cast<std::int64_t>(draw.Seconds(faults.max_stall_s) * 1e9);
      ++faulted.secondary_stalls;
    }
    if (held_ns > 0) SleepUntilMonotonicNs(MonotonicNowNs() + held_ns);
    const std::int64_t woke = MonotonicNowNs();
    // Woken far too late: hold the state over the missed periods, as the daemon does.
    const auto missed = static_cast<std::int64_t>(static_cast<double>(woke - release) / period_ns);
    if (missed > AsyncRegions::kSkipAfterLatePeriods) {
      regions.SkipRegion(a, missed * substeps);
      ++faulted.skips;
    }
    for (int q = 0; q < substeps; ++q) regions.StepRegion(a);
    monitor.Record(release, woke, MonotonicNowNs());
  }
}

}  // namespace

TrialResult RealTimeSchedule::RunTrial() {
  HAPTICSIM_THROW_UNLESS(!regions_.partition().proxy_contact(),
                         "a stroke on the regions runs in virtual time only (RunRegionStroke)");
  const Scene& scene = regions_.partition().scene();
  const ContactTrajectory trajectory(scene.input, regions_.partition().contact_normal());
  const int count = regions_.num_regions();
  const double dt = 1.0 / regions_.schedule(kPrimaryRegion).rate_hz;
  const long steps = scene.num_steps();
  const int primary_substeps = regions_.schedule(kPrimaryRegion).substeps;
  regions_.Reset();
  TrialResult result;
  result.stability = regions_.schedule(kPrimaryRegion).alone;
  TrialRecorder recorder(trajectory, dt, steps, &result);

  const RunGrid grid = MakeGrid(regions_, stretch_, steps);
  std::vector<std::unique_ptr<DeadlineMonitor>> monitors;
  for (int a = 0; a < count; ++a) {
    monitors.push_back(
        std::make_unique<DeadlineMonitor>(grid.nominal_ticks[a] * grid.tick_ns * 1e-9));
  }
  std::atomic<bool> primary_done{false};
  std::vector<FaultCounts> counts(static_cast<size_t>(count));
  std::vector<std::thread> threads;
  for (int a = 1; a < count; ++a) {
    threads.emplace_back([&, a] {
      RunSecondary(regions_, grid, a, faults_, *monitors[a], counts[a], primary_done);
    });
  }

  DeadlineMonitor& monitor = *monitors[kPrimaryRegion];
  FaultDraw draw(faults_.seed, kPrimaryRegion);
  const std::int64_t period_ticks = grid.nominal_ticks[kPrimaryRegion];
  const double period_ns = period_ticks * grid.tick_ns;
  for (long n = 0; n <= steps; ++n) {
    const std::int64_t release =
        grid.origin_ns + static_cast<std::int64_t>(n * period_ticks * grid.tick_ns);
    SleepUntilMonotonicNs(release);
    if (draw.Happens(faults_.primary_late_wakes_per_s, period_ns * 1e-9)) {
      // Late: the periods it missed are then stepped back to back, as their releases have passed.
      SleepUntilMonotonicNs(
          MonotonicNowNs() +
          static_cast<std::int64_t>(draw.Periods(faults_.max_late_periods) * period_ns));
      ++counts[kPrimaryRegion].primary_late_wakes;
    }
    const std::int64_t woke = MonotonicNowNs();
    const double t = n * dt;
    std::array<double, 3> r{};
    for (int q = 1; q <= primary_substeps; ++q) {
      const std::array<double, 3> rq =
          regions_.StepPrimary(trajectory.DisplacementAt(t + q * dt / primary_substeps));
      if (q == 1) r = rq;
    }
    monitor.Record(release, woke, MonotonicNowNs());
    if (!recorder.Record(n, r)) break;  // not finite: the trial ends there
  }
  primary_done.store(true, std::memory_order_release);
  for (std::thread& thread : threads) thread.join();
  stats_.clear();
  counts_ = {};
  for (const FaultCounts& c : counts) counts_ += c;
  for (int a = 0; a < count; ++a) {
    result.wall_time_s += regions_.compute_seconds(a);
    stats_.push_back(StatsOf(*monitors[a], stretch_ / regions_.schedule(a).rate_hz));
  }
  return result;
}

}  // namespace hapticsim
