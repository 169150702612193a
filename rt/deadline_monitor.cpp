#include "rt/deadline_monitor.hpp"

#include <cmath>

namespace hapticsim {
namespace {

void StoreMax(std::atomic<std::int64_t>& target, std::int64_t value) noexcept {
  std::int64_t seen = target.load(std::memory_order_relaxed);
  while (value > seen && !target.compare_exchange_weak(seen, value, std::memory_order_relaxed)) {
  }
}

}  // namespace

int DeadlineMonitor::BinOf(std::int64_t ns) noexcept {
  if (ns <= 1000) return 0;
  const int bin = static_cast<int>(std::ceil(std::log(ns / 1000.0) / std::log(1.25)));
  return bin < kBins ? bin : kBins - 1;
}

double DeadlineMonitor::BinUpperEdgeS(int bin) noexcept { return 1e-6 * std::pow(1.25, bin); }

void DeadlineMonitor::Record(std::int64_t release_ns, std::int64_t woke_ns,
                             std::int64_t done_ns) noexcept {
  const std::int64_t lateness = woke_ns - release_ns;
  const std::int64_t execution = done_ns - woke_ns;
  cycles_.fetch_add(1, std::memory_order_relaxed);
  StoreMax(worst_lateness_ns_, lateness);
  StoreMax(recent_lateness_ns_, lateness);
  StoreMax(recent_max_exec_ns_, execution);
  histogram_[BinOf(execution)].fetch_add(1, std::memory_order_relaxed);
  if (lateness > period_ns_ || done_ns > release_ns + period_ns_) {
    misses_.fetch_add(1, std::memory_order_relaxed);
    events_.Push({release_ns, lateness, execution});
  }
  last_done_ns_.store(done_ns, std::memory_order_release);
}

DeadlineSnapshot DeadlineMonitor::TakeSnapshot() noexcept {
  DeadlineSnapshot s;
  s.period_s = period_ns_ * 1e-9;
  s.cycles = cycles_.load(std::memory_order_relaxed);
  s.misses = misses_.load(std::memory_order_relaxed);
  s.worst_lateness_s = worst_lateness_ns_.load(std::memory_order_relaxed) * 1e-9;
  s.recent_worst_lateness_s = recent_lateness_ns_.exchange(0, std::memory_order_relaxed) * 1e-9;
  s.recent_execution_max_s = recent_max_exec_ns_.exchange(0, std::memory_order_relaxed) * 1e-9;
  std::array<std::int64_t, kBins> recent{};
  for (int b = 0; b < kBins; ++b) {
    const std::int64_t now = histogram_[b].load(std::memory_order_relaxed);
    recent[b] = now - previous_[b];
    previous_[b] = now;
    s.recent_cycles += recent[b];
  }
  auto quantile = [&](double q) {
    const auto rank =
        static_cast<std::int64_t>(std::ceil(q * static_cast<double>(s.recent_cycles)));
    std::int64_t seen = 0;
    for (int b = 0; b < kBins; ++b) {
      seen += recent[b];
      if (seen >= rank && seen > 0) return BinUpperEdgeS(b);
    }
    return 0.0;
  };
  s.recent_execution_p50_s = quantile(0.5);
  s.recent_execution_p99_s = quantile(0.99);
  return s;
}

}  // namespace hapticsim
