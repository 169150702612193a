#pragma once

#include <array>
#include <atomic>
#include <cstdint>

#include "rt/spsc_ring.hpp"

namespace hapticsim {

/** One late period of a real-time thread, as handed to the logging thread. */
struct DeadlineEvent {
  std::int64_t release_ns = 0;    ///< when the period should have started (CLOCK_MONOTONIC)
  std::int64_t lateness_ns = 0;   ///< wake-up after the release
  std::int64_t execution_ns = 0;  ///< the period's compute time
};

/** What the supervisor reads of a periodic thread. */
struct DeadlineSnapshot {
  double period_s = 0;
  std::int64_t cycles = 0;
  std::int64_t misses = 0;             ///< started late by more than a period, or overran it
  double worst_lateness_s = 0;         ///< since the start
  double recent_worst_lateness_s = 0;  ///< since the previous snapshot
  double recent_execution_p50_s = 0;   ///< since the previous snapshot (bin upper edges)
  double recent_execution_p99_s = 0;
  double recent_execution_max_s = 0;
  std::int64_t recent_cycles = 0;
};

/**
 * Deadline bookkeeping of one periodic real-time thread. Record() is called by that thread once
 * per period and only touches atomics and a lock-free ring (no allocation, lock or I/O). The
 * supervisor thread takes snapshots (execution-time percentiles from a fixed histogram: the
 * difference since its previous snapshot) and drains the miss events for the logger.
 */
class DeadlineMonitor {
 public:
  /** Histogram bins: 1 µs · 1.25^i, i < kBins (up to about 2.8 s). */
  static constexpr int kBins = 72;
  using EventRing = SpscRing<DeadlineEvent, 1024>;

  explicit DeadlineMonitor(double period_s)
      : period_ns_(static_cast<std::int64_t>(period_s * 1e9)) {}

  /**
   * Continues the run-long counts (periods, misses, worst lateness) of the monitor this one
   * replaces, so a thread's statistics survive a reconfiguration. Before the thread starts.
   */
  void CarryOver(const DeadlineMonitor& previous) noexcept {
    cycles_.store(previous.cycles_.load());
    misses_.store(previous.misses_.load());
    worst_lateness_ns_.store(previous.worst_lateness_ns_.load());
  }

  /** The periodic thread, after each period. */
  void Record(std::int64_t release_ns, std::int64_t woke_ns, std::int64_t done_ns) noexcept;

  /** The supervisor thread. */
  DeadlineSnapshot TakeSnapshot() noexcept;
  /** The supervisor thread: late periods, oldest first. */
  bool PopEvent(DeadlineEvent* event) noexcept { return events_.Pop(event); }
  /** Events lost because the ring was full (the logger fell behind). */
  std::size_t dropped_events() const noexcept { return events_.dropped(); }
  /** CLOCK_MONOTONIC of the last finished period, ns (0 before the first): the watchdog's pulse. */
  std::int64_t last_done_ns() const noexcept {
    return last_done_ns_.load(std::memory_order_acquire);
  }

  static int BinOf(std::int64_t ns) noexcept;
  static double BinUpperEdgeS(int bin) noexcept;

 private:
  std::int64_t period_ns_;
  std::atomic<std::int64_t> cycles_{0}, misses_{0}, worst_lateness_ns_{0}, recent_lateness_ns_{0};
  std::atomic<std::int64_t> recent_max_exec_ns_{0}, last_done_ns_{0};
  std::array<std::atomic<std::int64_t>, kBins> histogram_{};
  std::array<std::int64_t, kBins> previous_{};  // supervisor's copy at its last snapshot
  EventRing events_;
};

}  // namespace hapticsim
