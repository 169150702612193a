#pragma once

#include <atomic>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <memory>

namespace hapticsim {

/**
 * The newest values of a fixed number of doubles, written by one thread and read by any:
 * SeqlockSlot's protocol for a length chosen at run time (a region's part of the object's
 * surface). The values are stored as relaxed atomic words, so a reader racing the writer retries
 * instead of keeping a torn array, and there is no data race for the memory model.
 *
 * Write() never blocks, allocates or throws; neither does TryRead(). The array is allocated
 * once, by the constructor.
 */
class SeqlockArray {
 public:
  explicit SeqlockArray(std::size_t size)
      : size_(size), words_(std::make_unique<std::atomic<std::uint64_t>[]>(size)) {
    for (std::size_t i = 0; i < size_; ++i) words_[i].store(0, std::memory_order_relaxed);
  }

  std::size_t size() const { return size_; }

  /** Single writer: value i is value_at(i), a double. */
  template <typename ValueAt>
  void Write(ValueAt value_at) noexcept {
    const std::uint64_t seq = sequence_.load(std::memory_order_relaxed);
    sequence_.store(seq + 1, std::memory_order_relaxed);  // odd: writing
    std::atomic_thread_fence(std::memory_order_release);
    for (std::size_t i = 0; i < size_; ++i) {
      words_[i].store(std::bit_cast<std::uint64_t>(static_cast<double>(value_at(i))),
                      std::memory_order_relaxed);
    }
    sequence_.store(seq + 2, std::memory_order_release);  // even: consistent
  }

  /**
   * Any thread: copies the values into out[0 … size). False (out possibly half written) when
   * nothing was written yet or a write raced the read: read again.
   */
  bool TryRead(double* out) const noexcept {
    const std::uint64_t before = sequence_.load(std::memory_order_acquire);
    if (before == 0 || (before & 1)) return false;
    for (std::size_t i = 0; i < size_; ++i) {
      out[i] = std::bit_cast<double>(words_[i].load(std::memory_order_relaxed));
    }
    std::atomic_thread_fence(std::memory_order_acquire);
    return sequence_.load(std::memory_order_relaxed) == before;
  }

  /** Completed writes so far. */
  std::uint64_t writes() const noexcept { return sequence_.load(std::memory_order_acquire) / 2; }

 private:
  std::size_t size_;
  std::unique_ptr<std::atomic<std::uint64_t>[]> words_;
  std::atomic<std::uint64_t> sequence_{0};
};

}  // namespace hapticsim
