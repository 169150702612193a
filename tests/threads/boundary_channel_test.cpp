#include "core/boundary_channel.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <thread>
#include <vector>

namespace hapticsim {
namespace {

TEST(BoundaryChannel, ReadsNothingBeforeThePublication) {
  BoundaryChannel dut(3);
  BoundaryChannel::Snapshot a, b;
  a.values.resize(3);
  b.values.resize(3);
  EXPECT_FALSE(dut.TryReadLatestTwo(&a, &b));
}

TEST(BoundaryChannel, GivesTheNewestTwoInOrder) {
  BoundaryChannel dut(2);
  BoundaryChannel::Snapshot newer, older;
  newer.values.resize(2);
  older.values.resize(2);
  const std::vector<double> first{1, 2}, second{3, 4}, third{5, 6};
  dut.Publish(0.001, first);
  ASSERT_TRUE(dut.TryReadLatestTwo(&newer, &older));
  EXPECT_EQ(newer.values[1], 2);
  EXPECT_EQ(older.values[1], 2);  // only one so far: both are it
  dut.Publish(0.002, second);
  dut.Publish(0.003, third);
  ASSERT_TRUE(dut.TryReadLatestTwo(&newer, &older));
  EXPECT_DOUBLE_EQ(newer.time_s, 0.003);
  EXPECT_DOUBLE_EQ(older.time_s, 0.002);
  EXPECT_EQ(newer.values[0], 5);
  EXPECT_EQ(older.values[0], 3);
  EXPECT_EQ(newer.generation, older.generation + 1);
}

// A writer publishes 10⁶ snapshots whose every value encodes the generation; a reader on another
// thread checks that every snapshot it copies is whole (all values from one generation) and that
// the pair is consecutive.
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
  BoundaryChannel::Snapshot newer, older;
  newer.values.resize(kWidth);
  older.values.resize(kWidth);
  std::uint64_t reads = 0, torn = 0, out_of_order = 0, last_seen = 0, went_back = 0;
  while (!done.load()) {
    if (!dut.TryReadLatestTwo(&newer, &older)) continue;
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
}

}  // namespace
}  // namespace hapticsim
