#pragma once
// The device input's way from hapticsimd's I/O thread to its primary thread (HapticLoop).

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>

#include "rt/futex.hpp"
#include "rt/seqlock_slot.hpp"
#include "rt/spsc_ring.hpp"

namespace hapticsim {

/** An accepted device input, as the I/O thread hands it to the primary thread. */
struct DeviceSample {
  std::int64_t seq = -1;
  std::int64_t received_ns = 0;  ///< CLOCK_MONOTONIC when it arrived
  std::array<double, 3> position_m{};
  bool latest_rejected = false;  ///< the newest message after this one was refused
};

/**
 * Device inputs from one producer (the I/O thread) to one consumer (the primary thread), and the
 * consumer's wait for the next one when it has nothing to do.
 *
 * Every input offered reaches the consumer in order through an SPSC ring. A full ring (a consumer
 * stalled for kRingSize inputs) drops the input, but the newest still arrives: it is written to a
 * seqlock slot first, so a consumer that sees the ring's drop count move finds it, or a newer one,
 * there. The ring and the slot carry their own memory orders (SpscRing, SeqlockSlot).
 *
 * The wait is a futex on an arrival count. The producer's increment of the count and its read of
 * the consumer's waiting flag, and the consumer's store of that flag and its read of the count,
 * are sequentially consistent: of the two threads at least one sees the other's write, so either
 * the consumer sees the arrival and does not wait, or the producer sees it waiting and wakes it.
 * (With acquire and release alone both could miss each other, and an input would wait out the
 * timeout.) Nudge() moves the count without an input, for a stop or a reconfiguration.
 *
 * Offer(), Drain() and the wait never allocate or lock; only the wait blocks.
 */
class InputHandoff {
 public:
  static constexpr std::size_t kRingSize = 256;

  /** The producer thread. */
  void Offer(const DeviceSample& sample) noexcept {
    slot_.Write(sample);  // first: see the class comment
    ring_.Push(sample);
    Nudge();
  }

  /** Any thread: a waiting consumer comes round now, and one about to wait does not. */
  void Nudge() noexcept {
    arrivals_.fetch_add(1);  // sequentially consistent: see the class comment
    if (waiting_.load()) FutexWakeAll(&arrivals_);
  }

  /**
   * The consumer: `take(sample)` for every input offered since the last Drain, oldest first — at
   * most the ring's worth, so a producer as fast as the consumer cannot hold it — and then the
   * newest once more if the ring dropped inputs meanwhile (those in between are lost). The
   * arrivals counted before it started are the ones a later WaitForArrival does not wait for.
   */
  template <typename Take>
  void Drain(Take&& take) noexcept {
    arrivals_seen_ = arrivals_.load();
    DeviceSample sample;
    for (std::size_t n = 0; n < kRingSize && ring_.Pop(&sample); ++n) take(sample);
    if (ring_.dropped() != dropped_seen_ && slot_.Read(&sample)) {
      dropped_seen_ = ring_.dropped();
      take(sample);
    }
  }

  /**
   * The consumer: waits until an input is offered or Nudge() is called after the last Drain began,
   * at most `timeout_s` — not at all if one was, or if `must_not_wait()` (checked once the waiting
   * flag is up, so a condition set before a Nudge is seen) is true.
   */
  template <typename Predicate>
  void WaitForArrival(double timeout_s, Predicate&& must_not_wait) noexcept {
    waiting_.store(true);
    if (arrivals_.load() == arrivals_seen_ && !must_not_wait()) {
      FutexWait(&arrivals_, arrivals_seen_, timeout_s);
    }
    waiting_.store(false);
  }

  /** Inputs the ring dropped because it was full. Any thread. */
  std::size_t dropped() const noexcept { return ring_.dropped(); }

 private:
  SpscRing<DeviceSample, kRingSize> ring_;  // every input offered, in order
  SeqlockSlot<DeviceSample> slot_;          // the newest, for when the ring was full
  std::atomic<std::uint32_t> arrivals_{0};  // inputs offered and nudges: the futex word
  std::atomic<bool> waiting_{false};        // the consumer is in (or about to enter) its wait
  std::uint32_t arrivals_seen_ = 0;         // consumer: arrivals_ when its last Drain began
  std::size_t dropped_seen_ = 0;            // consumer: ring_.dropped() when it last looked
};

}  // namespace hapticsim
