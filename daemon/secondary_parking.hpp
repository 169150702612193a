#pragma once
// How hapticsimd's primary thread parks the secondary region threads when the regions are at rest
// and wakes them on a touch (HapticLoop's "sleeping at rest").

#include <array>
#include <atomic>
#include <cstdint>

#include "rt/futex.hpp"

namespace hapticsim {

/**
 * The primary ↔ secondaries protocol of sleeping at rest, for up to kMaxRegions regions (region 0
 * is the primary's own and has no slot use).
 *
 * 1. Watching. The primary opens a numbered watch (StartWatch). Before each step a secondary asks
 *    MayStep(); while a watch is open and its region is at rest, it stores that watch's number as
 *    found at rest. A finding from before a touch closed the watch cannot count in a later one.
 * 2. Parking. Once every secondary was found at rest in the current watch (AllAtRest), the primary
 *    raises the park flag (Park). Each secondary's next MayStep() answers false and marks it
 *    parked; it then blocks in WaitForWake() on the wake generation (a futex).
 * 3. Waking. Wake(origin) clears the marks and the flag, stores where the secondaries restart
 *    (origin, or −1 to carry on on their own grid) and moves the generation, waking them.
 *
 * Memory order:
 * - Every store the primary makes before it opens a watch or raises the park flag is a release
 *   that the secondary's acquire pairs with.
 * - A secondary's "found at rest" and "parked" stores are releases; the primary's acquire loads of
 *   them make that region's last step visible, so once AllParked() the primary may read and reset
 *   every region's state.
 * - Wake's stores are relaxed and then published by the generation's release increment; a
 *   secondary acquires the generation before it reads where to restart. A secondary reads the
 *   generation before it asks MayStep(), so a wake in between ends its wait at once: no wake is
 *   lost.
 * Nothing here allocates; only WaitForWake() blocks.
 */
template <int kMaxRegions>
class SecondaryParking {
 public:
  /** While no region thread runs (a reconfiguration, a start): awake, nothing parked. */
  void Forget() noexcept {
    park_.store(false);
    watch_.store(0);
    for (auto& parked : parked_) parked.store(false);
    wake_origin_ns_.store(-1);
  }

  // The primary thread.
  /** Opens a new watch for rest (numbered, never 0). */
  void StartWatch() noexcept {
    watches_ = watches_ == UINT32_MAX ? 1 : watches_ + 1;
    watch_.store(watches_, std::memory_order_release);
  }
  /** Closes the watch: no finding from it counts any more. */
  void StopWatch() noexcept { watch_.store(0, std::memory_order_relaxed); }
  /** The open watch (0: none). */
  std::uint32_t watch() const noexcept { return watch_.load(std::memory_order_relaxed); }
  /** Every region 1 … `secondaries` was found at rest in the open watch. */
  bool AllAtRest(int secondaries) const noexcept {
    const std::uint32_t watch = this->watch();
    if (watch == 0) return false;
    for (int a = 1; a <= secondaries; ++a) {
      if (at_rest_in_watch_[a].load(std::memory_order_acquire) != watch) return false;
    }
    return true;
  }
  /** Asks every secondary to park before its next step. */
  void Park() noexcept { park_.store(true, std::memory_order_release); }
  /** Every region 1 … `secondaries` has parked (their states are the primary's to read). */
  bool AllParked(int secondaries) const noexcept {
    for (int a = 1; a <= secondaries; ++a) {
      if (!parked_[a].load(std::memory_order_acquire)) return false;
    }
    return true;
  }
  /** Releases the parked secondaries, to restart at `origin_ns` (−1: where they were). */
  void Wake(std::int64_t origin_ns) noexcept {
    wake_origin_ns_.store(origin_ns, std::memory_order_relaxed);
    for (auto& parked : parked_) parked.store(false, std::memory_order_relaxed);
    park_.store(false, std::memory_order_relaxed);
    generation_.fetch_add(1, std::memory_order_release);  // publishes the stores above
    FutexWakeAll(&generation_);
  }
  /** Any thread: every waiting secondary comes round now (to see a stop). */
  void WakeAll() noexcept {
    generation_.fetch_add(1);
    FutexWakeAll(&generation_);
  }

  // A secondary region's thread.
  /** The wake generation: read before MayStep(), waited on when that says park. */
  std::uint32_t generation() const noexcept { return generation_.load(std::memory_order_acquire); }
  /**
   * Before each step of `region`: false when it must park (and marks it parked). `at_rest()` is
   * asked only while a watch is open.
   */
  template <typename AtRest>
  bool MayStep(int region, AtRest&& at_rest) noexcept {
    if (park_.load(std::memory_order_acquire)) {
      parked_[region].store(true, std::memory_order_release);  // publishes its last step's writes
      return false;
    }
    const std::uint32_t watch = watch_.load(std::memory_order_acquire);
    if (watch != 0 && at_rest()) at_rest_in_watch_[region].store(watch, std::memory_order_release);
    return true;
  }
  /**
   * Blocks while the generation is still `generation` and `stop` is not set, coming round at
   * least every `timeout_s`; then where to restart (−1: carry on on its own grid).
   */
  std::int64_t WaitForWake(std::uint32_t generation, const std::atomic<bool>& stop,
                           double timeout_s) noexcept {
    while (generation_.load(std::memory_order_acquire) == generation &&
           !stop.load(std::memory_order_acquire)) {
      FutexWait(&generation_, generation, timeout_s);
    }
    return wake_origin_ns_.load(std::memory_order_relaxed);
  }

 private:
  std::atomic<bool> park_{false};
  std::array<std::atomic<bool>, kMaxRegions> parked_{};
  std::atomic<std::uint32_t> watch_{0};
  std::array<std::atomic<std::uint32_t>, kMaxRegions> at_rest_in_watch_{};
  std::uint32_t watches_ = 0;  // the primary's: the last watch's number
  std::atomic<std::uint32_t> generation_{0};
  std::atomic<std::int64_t> wake_origin_ns_{-1};
};

}  // namespace hapticsim
