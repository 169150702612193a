#pragma once

#include <array>
#include <atomic>
#include <cstddef>
#include <type_traits>

namespace hapticsim {

/**
 * A bounded single-producer single-consumer queue of trivially copyable records: how the
 * real-time threads hand forces and deadline events to threads that may block (I/O, logging).
 * Push() and Pop() never block, lock or allocate; a full ring drops the new record and counts
 * it (the real-time thread never waits for a slow consumer).
 */
template <typename T, std::size_t Capacity>
class SpscRing {
  static_assert(std::is_trivially_copyable_v<T>);
  static_assert(Capacity >= 2 && (Capacity & (Capacity - 1)) == 0, "capacity: a power of two");

 public:
  /** Producer thread. False when full (the record is dropped and counted). */
  bool Push(const T& record) noexcept {
    const std::size_t head = head_.load(std::memory_order_relaxed);
    if (head - tail_.load(std::memory_order_acquire) == Capacity) {
      dropped_.fetch_add(1, std::memory_order_relaxed);
      return false;
    }
    slots_[head & (Capacity - 1)] = record;
    head_.store(head + 1, std::memory_order_release);
    return true;
  }

  /** Consumer thread. False when empty. */
  bool Pop(T* record) noexcept {
    const std::size_t tail = tail_.load(std::memory_order_relaxed);
    if (tail == head_.load(std::memory_order_acquire)) return false;
    *record = slots_[tail & (Capacity - 1)];
    tail_.store(tail + 1, std::memory_order_release);
    return true;
  }

  /** Records dropped because the ring was full. Any thread. */
  std::size_t dropped() const noexcept { return dropped_.load(std::memory_order_relaxed); }

 private:
  std::array<T, Capacity> slots_{};
  alignas(64) std::atomic<std::size_t> head_{0};
  alignas(64) std::atomic<std::size_t> tail_{0};
  std::atomic<std::size_t> dropped_{0};
};

}  // namespace hapticsim
