// Every device input gets its answer: the shared-memory input ring loses nothing a driver writes
// in quick succession (a real sealed segment, mapped twice as the daemon and the driver map it), and a primary period that took several inputs
// names them all in its answer.
#include <gtest/gtest.h>
#include <unistd.h>

#include <climits>
#include <cstdint>
#include <string>
#include <vector>

#include "daemon/haptic_loop.hpp"
#include "ipc/shm_device_client.hpp"

namespace hapticsim {
namespace {

TEST(ShmInputRing, InputsWrittenInQuickSuccessionAllReachTheDaemonInOrder) {
  shm::MappedSegment daemon = shm::MappedSegment::CreateSealed("hapticsim-test");
  shm::MappedSegment driver_mapping = shm::MappedSegment::Adopt(dup(daemon.fd()), "the test");
  auto write = [&](std::int64_t seq) {
    shm::ShmDeviceInput input;
    input.seq = seq;
    input.position_m[0] = input.position_m[1] = 0.1;
    shm::WriteDeviceInput(driver_mapping.segment(), input);
  };
  shm::ShmInputReader reader;
  std::vector<std::int64_t> seen;
  auto read = [&] {
    return reader.ReadNew(daemon.segment(), [&](const shm::ShmDeviceInput& in) {
      seen.push_back(in.seq);
    });
  };
  EXPECT_EQ(read(), 0);
  for (int seq = 1; seq <= 5; ++seq) write(seq);  // one poll
  EXPECT_EQ(read(), 5);
  EXPECT_EQ(seen, (std::vector<std::int64_t>{1, 2, 3, 4, 5}));
  EXPECT_EQ(read(), 0);  // nothing new
  // A daemon that did not poll for 300 writes reads the newest kInputSlots − 1 (the slot after
  // the newest may be being written), in order.
  seen.clear();
  for (int seq = 6; seq <= 305; ++seq) write(seq);
  EXPECT_EQ(read(), shm::kInputSlots - 1);
  EXPECT_EQ(seen.front(), 307 - shm::kInputSlots);
  EXPECT_EQ(seen.back(), 305);
  // Wild indexes from a broken or hostile writer: inside the ring, at most the ring, and the
  // driver's next write is read after each.
  const std::int64_t wild[] = {std::int64_t{1} << 62, INT64_MAX, -100, INT64_MIN, 3};
  std::int64_t seq = 306;
  for (const std::int64_t index : wild) {
    daemon.segment().newest_input.store(index);
    EXPECT_LE(read(), shm::kInputSlots - 1) << index;
    seen.clear();
    write(seq);
    EXPECT_GE(read(), 1) << index;
    ASSERT_FALSE(seen.empty()) << index;
    EXPECT_EQ(seen.back(), seq) << index;
    ++seq;
  }
}

// Through the primary period: two inputs handed over within one period are both used and both
// named by that period's answer (first_seq … seq); before, the older one was neither.
TEST(InputAnswers, APeriodThatTookTwoInputsAnswersBoth) {
  Scene scene;
  scene.adaptivity.primary_size = 3;
  HapticLoop loop(scene, HapticLoop::Options{});
  std::int64_t now = 1'000'000'000;
  ForceRecord record;
  std::vector<std::pair<std::int64_t, std::int64_t>> answered;  // (first_seq, seq)
  auto period = [&] {
    loop.PrimaryPeriod(now, now);
    while (loop.forces().Pop(&record)) answered.emplace_back(record.first_seq, record.seq);
    now += 1'000'000;
  };
  loop.OfferInput(DeviceSample{1, now, {0.125, 0.125, -0.002}, false});
  period();
  loop.OfferInput(DeviceSample{2, now - 500'000, {0.125, 0.125, -0.002}, false});
  loop.OfferInput(DeviceSample{3, now, {0.125, 0.125, -0.002}, false});
  period();
  period();  // no input: the same one answered again, naming no other
  loop.OfferInput(DeviceSample{4, now, {0.125, 0.125, -0.002}, false});
  loop.OfferInput(DeviceSample{6, now, {0.125, 0.125, -0.002}, false});  // 5 never came
  period();
  const std::vector<std::pair<std::int64_t, std::int64_t>> expected = {
      {1, 1}, {2, 3}, {3, 3}, {6, 6}};
  EXPECT_EQ(answered, expected);
}

}  // namespace
}  // namespace hapticsim
