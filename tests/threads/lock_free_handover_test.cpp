// The lock-free hand-overs between hapticsimd's threads, under contention (and under
// ThreadSanitizer in scripts/test.sh): the newest-value seqlock slot and the SPSC ring.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdint>
#include <thread>

#include "rt/seqlock_slot.hpp"
#include "rt/spsc_ring.hpp"

namespace hapticsim {
namespace {

// A record whose fields must always agree: a torn read would break the relation.
struct Checked {
  std::int64_t a = 0, b = 0, c = 0;
};

TEST(SeqlockSlot, ReadersNeverSeeATornValue) {
  SeqlockSlot<Checked> slot;
  // The writer goes on until the reader has read many values while it writes (or a cap), so the
  // two really overlap whatever the scheduler does.
  constexpr std::int64_t kReadsWanted = 100'000, kWriteCap = 500'000'000;
  std::atomic<std::int64_t> reads{0};
  std::atomic<bool> done{false};
  std::thread writer([&] {
    for (std::int64_t i = 1; i <= kWriteCap && reads.load(std::memory_order_relaxed) < kReadsWanted;
         ++i) {
      slot.Write({i, 2 * i, 3 * i});
    }
    done = true;
  });
  std::int64_t last = 0;
  while (!done) {
    Checked value;
    if (slot.TryRead(&value)) {
      reads.fetch_add(1, std::memory_order_relaxed);
      ASSERT_EQ(value.b, 2 * value.a);
      ASSERT_EQ(value.c, 3 * value.a);
      ASSERT_GE(value.a, last);  // never older than what was seen
      last = value.a;
    }
  }
  writer.join();
  EXPECT_GE(reads.load(), kReadsWanted);
}

// Over shared memory the writer is another process, which can die between the two sequence
// stores: the slot is left odd ("being written") for good. Readers must read nothing from it,
// and the next writer (a restarted driver) must be read again.
TEST(SeqlockSlot, AWriterThatDiedMidWriteLeavesNothingReadableAndTheNextWriterIsRead) {
  SeqlockSlot<Checked> slot;
  slot.Write({1, 2, 3});
  // The sequence is the slot's first member (rt/seqlock_slot.hpp): a death mid-write leaves it
  // odd, exactly as this store does.
  auto& sequence = *reinterpret_cast<std::atomic<std::uint64_t>*>(&slot);
  ASSERT_EQ(sequence.load() % 2, 0u);
  sequence.store(sequence.load() + 1);
  Checked value;
  EXPECT_FALSE(slot.Read(&value)) << "a half-written value was read";
  slot.Write({4, 8, 12});  // the restarted writer
  ASSERT_TRUE(slot.Read(&value));
  EXPECT_EQ(value.a, 4);
  EXPECT_EQ(value.c, 12);
  slot.Write({5, 10, 15});
  ASSERT_TRUE(slot.Read(&value));
  EXPECT_EQ(value.a, 5);
}

TEST(SpscRing, DeliversInOrderAndCountsWhatAFullRingDrops) {
  SpscRing<Checked, 1024> ring;
  std::atomic<bool> done{false};
  constexpr std::int64_t kCount = 1'000'000;
  std::thread producer([&] {
    for (std::int64_t i = 1; i <= kCount; ++i) {
      while (!ring.Push({i, 2 * i, 3 * i})) {
      }
    }
    done = true;
  });
  std::int64_t expected = 1;
  Checked value;
  while (expected <= kCount) {
    if (ring.Pop(&value)) {
      ASSERT_EQ(value.a, expected);
      ASSERT_EQ(value.c, 3 * expected);
      ++expected;
    }
  }
  producer.join();
  SpscRing<Checked, 2> small;
  EXPECT_TRUE(small.Push({}));
  EXPECT_TRUE(small.Push({}));
  EXPECT_FALSE(small.Push({}));
  EXPECT_EQ(small.dropped(), 1u);
}

}  // namespace
}  // namespace hapticsim
