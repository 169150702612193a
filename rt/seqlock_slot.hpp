#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <cstring>
#include <type_traits>

namespace hapticsim {

/**
 * The newest value of a trivially copyable T, written by one thread and read by any: a seqlock
 * whose payload is stored as relaxed atomic words, so a reader racing a writer reads no torn
 * value it would keep (it retries) and no data race exists for the memory model.
 *
 * Write() never blocks or allocates. TryRead() returns false when a write was in progress (the
 * caller keeps its previous value or retries); it never blocks either.
 */
template <typename T>
class SeqlockSlot {
  static_assert(std::is_trivially_copyable_v<T>);
  static constexpr size_t kWords = (sizeof(T) + 7) / 8;

 public:
  SeqlockSlot() {
    for (auto& word : words_) word.store(0, std::memory_order_relaxed);
  }

  /** Single writer. */
  void Write(const T& value) noexcept {
    std::array<std::uint64_t, kWords> words{};
    std::memcpy(words.data(), &value, sizeof(T));
    std::uint64_t seq = sequence_.load(std::memory_order_relaxed);
    // Odd here: the previous writer (another process, over shared memory) died mid-write. Start
    // from the next even value, or every write from now on would read as torn.
    if (seq & 1) ++seq;
    sequence_.store(seq + 1, std::memory_order_relaxed);  // odd: writing
    std::atomic_thread_fence(std::memory_order_release);
    for (size_t i = 0; i < kWords; ++i) words_[i].store(words[i], std::memory_order_relaxed);
    sequence_.store(seq + 2, std::memory_order_release);  // even: consistent
  }

  /** Any thread. False (and *out untouched) when no value was written yet or a write raced. */
  bool TryRead(T* out) const noexcept {
    const std::uint64_t before = sequence_.load(std::memory_order_acquire);
    if (before == 0 || (before & 1)) return false;
    std::array<std::uint64_t, kWords> words{};
    for (size_t i = 0; i < kWords; ++i) words[i] = words_[i].load(std::memory_order_relaxed);
    std::atomic_thread_fence(std::memory_order_acquire);
    if (sequence_.load(std::memory_order_relaxed) != before) return false;
    std::memcpy(static_cast<void*>(out), words.data(), sizeof(T));
    return true;
  }

  /** Reads, retrying a few times past concurrent writes. */
  bool Read(T* out) const noexcept {
    for (int attempt = 0; attempt < 16; ++attempt) {
      if (TryRead(out)) return true;
    }
    return false;
  }

 private:
  std::atomic<std::uint64_t> sequence_{0};
  std::array<std::atomic<std::uint64_t>, kWords> words_;
};

}  // namespace hapticsim
