#include "core/regions/realtime_schedule.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <memory>
#include <random>
#include <thread>

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

TrialResult RealTimeSchedule::RunTrial() {
  const Scene& scene = regions_.partition().scene();
  const ContactTrajectory trajectory(scene.input, InwardNormal(scene.mesh, ContactNode(scene)));
  const int count = regions_.num_regions();
  const double dt = 1.0 / regions_.schedule(kPrimaryRegion).rate_hz;
  const long steps = scene.num_steps();
  const double tick_ns = stretch_ * 1e9 / static_cast<double>(regions_.ticks_per_second());
  const int primary_substeps = regions_.schedule(kPrimaryRegion).substeps;
  const std::int64_t primary_period_ticks =
      regions_.period_ticks(kPrimaryRegion) * primary_substeps;
  const std::int64_t end_ticks = (steps + 1) * primary_period_ticks;
  regions_.Reset();

  TrialResult result;
  result.stability = regions_.schedule(kPrimaryRegion).alone;
  TrialRecorder recorder(trajectory, dt, steps, &result);
  // Each thread wakes once per nominal period and takes that period's substeps in a row.
  std::vector<std::unique_ptr<DeadlineMonitor>> monitors;
  std::vector<std::int64_t> lead_ns(static_cast<size_t>(count), 0);
  std::vector<std::int64_t> nominal_ticks(static_cast<size_t>(count), 0);
  for (int a = 0; a < count; ++a) {
    nominal_ticks[a] = regions_.period_ticks(a) * regions_.schedule(a).substeps;
    monitors.push_back(std::make_unique<DeadlineMonitor>(nominal_ticks[a] * tick_ns * 1e-9));
    if (a > 0) {
      lead_ns[a] =
          lead_ns[a - 1] + static_cast<std::int64_t>(1.25 * nominal_ticks[a - 1] * tick_ns);
    }
  }

  // Wall-clock origin of simulation time 0, far enough ahead for the outer regions' leads.
  const std::int64_t origin_ns = MonotonicNowNs() + 20'000'000 + lead_ns.back();
  std::atomic<bool> primary_done{false};

  std::vector<FaultCounts> counts(static_cast<size_t>(count));
  std::vector<std::thread> threads;
  for (int a = 1; a < count; ++a) {
    threads.emplace_back([&, a] {
      DeadlineMonitor& monitor = *monitors[a];
      FaultCounts& faulted = counts[a];
      FaultDraw draw(faults_.seed, a);
      const std::int64_t period = nominal_ticks[a];
      const int substeps = regions_.schedule(a).substeps;
      const double period_ns = period * tick_ns;
      while (!primary_done.load(std::memory_order_acquire)) {
        const std::int64_t state = regions_.state_ticks(a);
        if (state >= end_ticks + period) break;
        const auto release = origin_ns + static_cast<std::int64_t>(state * tick_ns) - lead_ns[a];
        SleepUntilMonotonicNs(release);
        std::int64_t held_ns = 0;
        if (draw.Happens(faults_.secondary_lags_per_s, period_ns * 1e-9)) {
          held_ns = static_cast<std::int64_t>(draw.Periods(faults_.max_lag_periods) * period_ns);
          ++faulted.secondary_lags;
        } else if (draw.Happens(faults_.secondary_stalls_per_s, period_ns * 1e-9)) {
          held_ns = static_cast<std::int64_t>(draw.Seconds(faults_.max_stall_s) * 1e9);
          ++faulted.secondary_stalls;
        }
        if (held_ns > 0) SleepUntilMonotonicNs(MonotonicNowNs() + held_ns);
        const std::int64_t woke = MonotonicNowNs();
        // Woken far too late: hold the state over the missed periods, as the daemon does.
        const auto missed =
            static_cast<std::int64_t>(static_cast<double>(woke - release) / period_ns);
        if (missed > AsyncRegions::kSkipAfterLatePeriods) {
          regions_.SkipRegion(a, missed * substeps);
          ++faulted.skips;
        }
        for (int q = 0; q < substeps; ++q) regions_.StepRegion(a);
        monitor.Record(release, woke, MonotonicNowNs());
      }
    });
  }

  DeadlineMonitor& monitor = *monitors[kPrimaryRegion];
  FaultDraw draw(faults_.seed, kPrimaryRegion);
  const double period_ns = primary_period_ticks * tick_ns;
  for (long n = 0; n <= steps; ++n) {
    const std::int64_t release =
        origin_ns + static_cast<std::int64_t>(n * primary_period_ticks * tick_ns);
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
