#include "core/regions/boundary_channel.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <cstdio>
#include <thread>
#include <vector>

namespace hapticsim {
namespace {

TEST(BoundaryChannel, ReadsNothingBeforeThePublication) {
  BoundaryChannel dut(3);
  BoundaryChannel::ReadPair pair(3);
  EXPECT_FALSE(dut.TryReadLatestTwo(&pair));
}

TEST(BoundaryChannel, GivesTheNewestTwoInOrder) {
  BoundaryChannel dut(2);
  BoundaryChannel::ReadPair pair(2);
  const auto& newer = pair.newer;
  const auto& older = pair.older;
  const std::vector<double> first{1, 2}, second{3, 4}, third{5, 6};
  dut.Publish(0.001, first);
  ASSERT_TRUE(dut.TryReadLatestTwo(&pair));
  EXPECT_EQ(newer.values[1], 2);
  EXPECT_EQ(older.values[1], 2);  // only one so far: both are it
  dut.Publish(0.002, second);
  dut.Publish(0.003, third);
  ASSERT_TRUE(dut.TryReadLatestTwo(&pair));
  EXPECT_DOUBLE_EQ(newer.time_s, 0.003);
  EXPECT_DOUBLE_EQ(older.time_s, 0.002);
  EXPECT_EQ(newer.values[0], 5);
  EXPECT_EQ(older.values[0], 3);
  EXPECT_EQ(newer.generation, older.generation + 1);
}

// A writer publishes 10⁶ snapshots whose every value encodes the generation; a reader on another
// thread checks that every snapshot it copies is whole (all values from one generation) and that
// the pair is consecutive — and that a read that fails leaves the pair it had exactly as it was
// (the regions go on with it: a failed read once left new values under an old time stamp).
TEST(BoundaryChannel, EveryReadIsAConsistentSnapshotUnderContention) {
  constexpr int kWidth = 64;
  constexpr std::uint64_t kPublications = 1'000'000;
  BoundaryChannel dut(kWidth);
  std::atomic<bool> done{false};
  std::thread writer([&] {
    std::vector<double> values(kWidth);
    for (std::uint64_t g = 1; g <= kPublications; ++g) {
      for (int i = 0; i < kWidth; ++i) values[i] = static_cast<double>(g) * 1000.0 + i;
      dut.Publish(static_cast<double>(g) * 1e-3, values);
    }
    done.store(true);
  });
  BoundaryChannel::ReadPair pair(kWidth);
  const auto& newer = pair.newer;
  const auto& older = pair.older;
  std::uint64_t reads = 0, torn = 0, out_of_order = 0, last_seen = 0, went_back = 0;
  std::uint64_t failed = 0, changed_by_failure = 0;
  while (!done.load()) {
    if (!dut.TryReadLatestTwo(&pair)) {
      ++failed;
      if (reads > 0 &&
          (newer.generation != last_seen ||
           newer.values[kWidth - 1] != static_cast<double>(last_seen) * 1000.0 + kWidth - 1 ||
           older.values[0] != static_cast<double>(older.generation) * 1000.0)) {
        ++changed_by_failure;
      }
      continue;
    }
    ++reads;
    for (int i = 0; i < kWidth; ++i) {
      if (newer.values[i] != static_cast<double>(newer.generation) * 1000.0 + i) ++torn;
      if (older.values[i] != static_cast<double>(older.generation) * 1000.0 + i) ++torn;
    }
    if (newer.generation != older.generation + 1 && newer.generation != 1) ++out_of_order;
    if (newer.time_s != static_cast<double>(newer.generation) * 1e-3) ++torn;
    if (newer.generation < last_seen) ++went_back;
    last_seen = newer.generation;
  }
  writer.join();
  EXPECT_GT(reads, 1000u);
  EXPECT_EQ(torn, 0u);
  EXPECT_EQ(out_of_order, 0u);
  EXPECT_EQ(went_back, 0u);
  EXPECT_EQ(changed_by_failure, 0u) << "of " << failed << " failed reads";
  std::printf("%llu reads, %llu failed\n", static_cast<unsigned long long>(reads),
              static_cast<unsigned long long>(failed));
}

}  // namespace
}  // namespace hapticsim
