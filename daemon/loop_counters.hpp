#pragma once
// What hapticsimd's region threads count and publish for the supervisor, the status message and
// the tests (HapticLoop's accessors read them).

#include <array>
#include <atomic>
#include <cstdint>

#include "core/regions/async_regions.hpp"

namespace hapticsim {

/** A value with one writer, stored and read relaxed: it tells a reader nothing else. */
template <typename T>
class Relaxed {
 public:
  constexpr explicit Relaxed(T initial = T{}) noexcept : value_(initial) {}
  void Set(T value) noexcept { value_.store(value, std::memory_order_relaxed); }
  /** The writer: keeps the most it was set to. */
  void RaiseTo(T value) noexcept {
    if (value > this->value()) Set(value);
  }
  T value() const noexcept { return value_.load(std::memory_order_relaxed); }

 private:
  std::atomic<T> value_;
};

/** A count with one writer, stored and read relaxed. */
class RelaxedCount {
 public:
  void Add(std::int64_t n = 1) noexcept { count_.fetch_add(n, std::memory_order_relaxed); }
  std::int64_t value() const noexcept { return count_.load(std::memory_order_relaxed); }

 private:
  std::atomic<std::int64_t> count_{0};
};

/**
 * The loop's counters and gauges. Memory order: each has one writer (the primary thread; a
 * secondary's stalls and skips, that secondary's thread) and is stored and read relaxed (Relaxed,
 * RelaxedCount). Each is a value of its own: no reader infers from one anything about another, or
 * about the regions — with one exception, the runaway count, which is incremented with release
 * after the energies it describes are stored, and read with acquire (runaways(), then
 * last_runaway()). None of them allocates, locks or blocks.
 */
template <int kMaxRegions>
struct LoopCounters {
  // Periods of the primary (each also flags its answer: see force_flags).
  RelaxedCount stale_periods;        ///< run on stale input (kInputStale)
  RelaxedCount paused_periods;       ///< answered while the regions were being replaced
  RelaxedCount limited_periods;      ///< the port guard limited the force (kForceLimited)
  RelaxedCount dissipating_periods;  ///< the port guard dissipated energy (kPortDissipating)
  Relaxed<std::int64_t> last_contact_ns;  ///< CLOCK_MONOTONIC of the last in contact (0: never)
  Relaxed<bool> in_contact;               ///< the newest period answered in contact

  // The port guard.
  RelaxedCount force_faults;  ///< faults latched
  RelaxedCount rearms;        ///< latched faults re-armed since
  Relaxed<bool> fault_latched;
  Relaxed<int> last_fault;  ///< PortGuard::Fault of the newest
  Relaxed<double> port_dissipated_j;

  // The coupling's energy balance.
  Relaxed<double> interface_backlog_j, interface_backlog_max_j;
  RelaxedCount balance_violations;

  // Sleeping at rest.
  Relaxed<bool> asleep, idle;
  RelaxedCount sleeps;
  Relaxed<std::int64_t> alive_ns;  ///< the primary's last wait for input that came round

  // The supervisor's requests from the primary.
  Relaxed<std::int64_t> wanted_node_code{-1};  ///< (ix · n + iy) · n + iz, −1: none
  Relaxed<bool> contact_waiting;
  Relaxed<bool> contact_following;  ///< a sliding tool's regions should follow its proxy

  // Per secondary region, written by its own thread.
  std::array<RelaxedCount, kMaxRegions> stalls, skipped_periods;

  /** The primary: a runaway of these regions, published with its energies. */
  void PublishRunaway(const RunawayEnergies& energies) noexcept {
    runaway_state_j_.store(energies.state_j, std::memory_order_relaxed);
    runaway_allowed_j_.store(energies.allowed_j, std::memory_order_relaxed);
    runaways_.fetch_add(1, std::memory_order_release);
  }
  /** Any thread: runaways counted; the energies of the one counted last are read after it. */
  std::int64_t runaways() const noexcept { return runaways_.load(std::memory_order_acquire); }
  RunawayEnergies last_runaway() const noexcept {
    return {runaway_state_j_.load(std::memory_order_relaxed),
            runaway_allowed_j_.load(std::memory_order_relaxed)};
  }

 private:
  std::atomic<std::int64_t> runaways_{0};
  std::atomic<double> runaway_state_j_{0}, runaway_allowed_j_{0};
};

}  // namespace hapticsim
