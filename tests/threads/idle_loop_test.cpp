// hapticsimd's loop on real threads and clocks with nothing touching the object: the secondary
// thread parks (no steps at all), the primary answers every input but steps nothing, and with no
// device it waits for input instead of running periods; an input wakes it at once and a touch
// wakes the regions.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <cstdio>
#include <functional>
#include <thread>
#include <vector>

#include "daemon/haptic_loop.hpp"
#include "tests/support/late_wakes.hpp"
#include "tests/support/play_device.hpp"
#include "tests/support/poll_until.hpp"
#include "tests/support/sanitized.hpp"

namespace hapticsim {
namespace {

using Clock = std::chrono::steady_clock;

// Under a sanitizer (kSanitized) every step is several times slower: latencies are not checked.

constexpr std::array<double, 3> kAbove{0.125, 0.125, -0.002};  // 2 mm off the front face

std::int64_t Cycles(HapticLoop& loop, RegionIndex region) {
  return loop.monitor(region).TakeSnapshot().cycles;
}

// Plays the device for `periods` periods from seq *seq on (and moves *seq past them).
std::vector<ForceRecord> Drive(HapticLoop& loop, std::int64_t* seq, int periods,
                               const std::function<std::array<double, 3>(int)>& tip) {
  std::vector<ForceRecord> forces = testing::PlayDevice(
      loop, periods, tip, [] { return true; }, *seq);
  *seq += periods;
  return forces;
}

TEST(IdleLoop, ParksTheSecondaryAnswersEveryInputAndWakesOnInputAndTouch) {
  Scene scene;
  scene.adaptivity.primary_size = 3;
  HapticLoop loop(scene, HapticLoop::Options{});
  ASSERT_GE(loop.regions().num_regions(), 2);
  loop.Start();
  std::int64_t seq = 0;
  auto above = [](int) { return kAbove; };

  // At rest from the start and untouched: asleep within a few periods.
  Drive(loop, &seq, 200, above);
  ASSERT_TRUE(loop.asleep());
  EXPECT_EQ(loop.sleeps(), 1);

  // Hovering: every input answered, the secondary region not stepped once.
  const std::int64_t secondary_before = Cycles(loop, 1);
  const std::vector<ForceRecord> hovering = Drive(loop, &seq, 300, above);
  EXPECT_EQ(Cycles(loop, 1), secondary_before) << "a parked secondary stepped";
  EXPECT_GE(hovering.size(), 295u);
  for (const ForceRecord& f : hovering) EXPECT_EQ(f.force_n[2], 0.0);

  // No device: once the input is stale the primary waits for input instead of running periods.
  EXPECT_TRUE(testing::PollUntil([&] { return loop.idle(); }));  // stale after 50 ms, then idle
  const std::int64_t primary_before = Cycles(loop, kPrimaryRegion);
  const auto wait_began = Clock::now();
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  const double waited_ms =
      std::chrono::duration<double, std::milli>(Clock::now() - wait_began).count();
  // Awake it would run a period a millisecond; idle, one per kIdleWait_s (20 ms) at most, over
  // however long this thread's sleep lasted (a busy machine oversleeps).
  EXPECT_LE(Cycles(loop, kPrimaryRegion) - primary_before, waited_ms / 20 + 5)
      << "in " << waited_ms << " ms";
  // A sign of life at least every kIdleWait_s: within 5 of them (under a sanitizer, 25).
  const std::int64_t alive_within_ns = kSanitized ? 500'000'000 : 100'000'000;
  EXPECT_GT(loop.primary_alive_ns(), HapticLoop::NowNs() - alive_within_ns) << "no sign of life";

  // An input after the silence is answered at once, not at the idle primary's next look round.
  int prompt = 0;
  for (int trial = 0; trial < 10; ++trial) {
    while (!loop.idle()) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    ForceRecord record;
    while (loop.forces().Pop(&record)) {
    }
    const std::int64_t sent = seq++;
    const auto start = Clock::now();
    loop.OfferInput(DeviceSample{sent, HapticLoop::NowNs(), kAbove, false});
    bool answered = false;
    while (!answered && Clock::now() - start < std::chrono::milliseconds(100)) {
      while (loop.forces().Pop(&record)) answered |= record.seq == sent;
      std::this_thread::sleep_for(std::chrono::microseconds(50));
    }
    EXPECT_TRUE(answered) << "trial " << trial;
    if (answered && Clock::now() - start < std::chrono::milliseconds(5)) ++prompt;
  }
  // Unwoken, an answer would wait for the primary's next look round (kIdleWait_s = 20 ms): under
  // 5 ms a quarter of the time, so 7 of 10 by chance 0.4 % of the time (3 slow ones are allowed
  // for a busy machine).
  if (!kSanitized) {
    EXPECT_GE(prompt, 7) << "of 10 inputs after a silence answered within 5 ms";
  }

  // A press wakes the regions: the secondary steps again and the object pushes back.
  const std::vector<ForceRecord> press = Drive(loop, &seq, 400, [](int n) {
    return std::array<double, 3>{0.125, 0.125, -0.002 + 0.007 * std::min(1.0, n / 300.0)};
  });
  EXPECT_FALSE(loop.asleep());
  EXPECT_GT(Cycles(loop, 1), secondary_before + 10) << "the secondary was not woken";
  double deepest = 0;
  for (const ForceRecord& f : press) deepest = std::min(deepest, f.force_n[2]);
  EXPECT_LT(deepest, -0.3) << "a 5 mm press pushes back with ~0.7 N";
  loop.Stop();
}

// An idle loop goes back on its release grid at the next release after an input, skipping the
// periods it waited through: tests that count answers near a late wake (late_wakes.hpp) read the
// periods answered after an idle wait on the new grid, not as all late on the old one.
TEST(IdleLoop, AfterAnIdleWaitTheAnswersAreReadOnTheGridItWentBackTo) {
  Scene scene;
  scene.adaptivity.primary_size = 3;
  HapticLoop loop(scene, HapticLoop::Options{});
  loop.Start();
  std::int64_t seq = 0;
  auto above = [](int) { return kAbove; };
  std::vector<ForceRecord> answers = Drive(loop, &seq, 300, above);
  ASSERT_TRUE(loop.asleep());
  EXPECT_TRUE(testing::PollUntil([&] { return loop.idle(); }));  // no device: stale, then idle
  const std::vector<ForceRecord> after = Drive(loop, &seq, 300, above);
  loop.Stop();
  answers.insert(answers.end(), after.begin(), after.end());

  std::vector<Wake> counted_on_one_grid, read_in_stretches;
  int stale = 0;
  for (const ForceRecord& f : answers) {
    const bool input_stale = (f.flags & force_flags::kInputStale) != 0;
    stale += input_stale;
    counted_on_one_grid.push_back({f.period, f.utime_us});
    read_in_stretches.push_back({f.period, f.utime_us, input_stale});
  }
  ASSERT_GT(stale, 0) << "no answer to stale input while the device was silent";
  auto late_in = [&](const std::vector<Wake>& wakes, size_t begin, size_t end) {
    const std::vector<bool> near = NearALateWake(wakes);
    int late = 0;
    for (size_t i = begin; i < end; ++i) late += !read_in_stretches[i].input_stale && near[i];
    return late;
  };
  auto late_after_the_wait = [&](const std::vector<Wake>& wakes) {
    return late_in(wakes, answers.size() - after.size(), answers.size());
  };
  // On one grid the whole second stretch is "late" by the ~150 periods skipped: the measure the
  // e2e re-centring test once failed on (657 of 1,600 answers). Read in stretches, only the
  // machine's own late wakes count (a quiet machine: none to a few).
  const int on_one_grid = late_after_the_wait(counted_on_one_grid);
  const int in_stretches = late_after_the_wait(read_in_stretches);
  // The machine's own: the answers before the wait, as late as it woke them.
  const int before_the_wait = late_in(read_in_stretches, 0, answers.size() - after.size());
  std::printf(
      "after the idle wait, of %zu answers: %d late counted on one grid, %d in stretches (%d "
      "before the wait)\n",
      after.size(), on_one_grid, in_stretches, before_the_wait);
  EXPECT_GT(on_one_grid, 250);
  // Read in stretches, the answers after the wait are read on their own grid: as late as if they
  // were all there was. (The loop flags the answers between the two drives stale; unflagged, the
  // stretches would run together and the old grid would count again.)
  std::vector<Wake> after_alone(read_in_stretches.end() - static_cast<std::ptrdiff_t>(after.size()),
                                read_in_stretches.end());
  const std::vector<bool> near_alone = NearALateWake(after_alone);
  int late_alone = 0;
  for (size_t i = 0; i < after_alone.size(); ++i) {
    late_alone += !after_alone[i].input_stale && near_alone[i];
  }
  EXPECT_EQ(in_stretches, late_alone);
  // And the loop went back on a grid at once, not running the periods it waited through back to
  // back (~150 late from the wait on): a machine that wakes many late (CI's once woke two in
  // three) makes as many late after the wait as before it, give or take. Not under a sanitizer,
  // whose slower periods finish late in runs of their own (TSan once: 93 after, 0 before).
  if (!kSanitized) {
    EXPECT_LT(in_stretches, 75 + before_the_wait);
  }
}

}  // namespace
}  // namespace hapticsim
