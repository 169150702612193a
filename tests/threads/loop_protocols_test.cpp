// The haptic loop's protocols between its threads, each on real threads of its own: the device
// input's hand-off (InputHandoff), the reconfiguration's handshake (RegionHandover), sleeping at
// rest (SecondaryParking), a secondary's sleep asked to stop (SecondarySleep) and the counters
// (LoopCounters, on a running HapticLoop). Under
// ThreadSanitizer a missing release/acquire pair shows as a data race on the plain data each test
// hands across; in any build, each test checks what the protocol promises.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <thread>
#include <vector>

#include "daemon/haptic_loop.hpp"
#include "daemon/input_handoff.hpp"
#include "daemon/region_handover.hpp"
#include "daemon/secondary_parking.hpp"
#include "rt/monotonic_clock.hpp"
#include "tests/support/play_device.hpp"
#include "tests/support/poll_until.hpp"

namespace hapticsim {
namespace {

using std::chrono::microseconds;
using std::chrono::milliseconds;

double SecondsSince(std::int64_t start_ns) { return (MonotonicNowNs() - start_ns) * 1e-9; }

// ---- InputHandoff -------------------------------------------------------------------------------

TEST(InputHandoff, EveryInputArrivesInOrderAndAWaitingConsumerWakesAtOnce) {
  InputHandoff handoff;
  constexpr int kInputs = 3000;
  std::thread producer([&] {
    for (int n = 0; n < kInputs; ++n) {
      handoff.Offer(DeviceSample{n, MonotonicNowNs(), {0, 0, -0.001 * n}, false});
      // Bursts of up to 8 back to back, then a gap the consumer waits through.
      if (n % 8 == 7) std::this_thread::sleep_for(microseconds(50 + n % 300));
    }
  });
  std::vector<std::int64_t> seqs;
  seqs.reserve(kInputs);
  double longest_wait_s = 0;
  int waits = 0;
  const std::int64_t give_up_ns = MonotonicNowNs() + 20'000'000'000;
  while (seqs.size() < static_cast<size_t>(kInputs) && MonotonicNowNs() < give_up_ns) {
    handoff.Drain([&](const DeviceSample& sample) { seqs.push_back(sample.seq); });
    if (seqs.size() == static_cast<size_t>(kInputs)) break;
    // A lost wake-up would wait out the whole second.
    const std::int64_t start = MonotonicNowNs();
    handoff.WaitForArrival(1.0, [] { return false; });
    longest_wait_s = std::max(longest_wait_s, SecondsSince(start));
    ++waits;
  }
  producer.join();
  handoff.Drain([&](const DeviceSample& sample) { seqs.push_back(sample.seq); });
  ASSERT_EQ(seqs.size(), static_cast<size_t>(kInputs));
  for (int n = 0; n < kInputs; ++n) ASSERT_EQ(seqs[n], n) << "out of order or lost";
  EXPECT_EQ(handoff.dropped(), 0u);
  EXPECT_GT(waits, 100) << "the consumer should have waited between bursts";
  EXPECT_LT(longest_wait_s, 0.5) << "a wait outlasted the input that should have ended it";
}

TEST(InputHandoff, AFullRingStillDeliversTheNewestAndCountsWhatItDropped) {
  InputHandoff handoff;
  const int offered = static_cast<int>(InputHandoff::kRingSize) + 44;
  for (int n = 0; n < offered; ++n) handoff.Offer(DeviceSample{n, n, {}, false});
  std::vector<std::int64_t> seqs;
  handoff.Drain([&](const DeviceSample& sample) { seqs.push_back(sample.seq); });
  ASSERT_EQ(seqs.size(), InputHandoff::kRingSize + 1);
  for (size_t n = 0; n < InputHandoff::kRingSize; ++n) EXPECT_EQ(seqs[n], std::int64_t(n));
  EXPECT_EQ(seqs.back(), offered - 1) << "the newest input must arrive";
  EXPECT_EQ(handoff.dropped(), 44u);
  seqs.clear();
  handoff.Drain([&](const DeviceSample& sample) { seqs.push_back(sample.seq); });
  EXPECT_TRUE(seqs.empty()) << "the newest is delivered once";
}

TEST(InputHandoff, ANudgeOrTheConditionEndsAWaitWithoutAnInput) {
  InputHandoff handoff;
  handoff.Drain([](const DeviceSample&) {});
  std::int64_t start = MonotonicNowNs();  // before the nudger: it nudges 20 ms after this or later
  std::thread nudger([&] {
    std::this_thread::sleep_for(milliseconds(20));
    handoff.Nudge();
  });
  handoff.WaitForArrival(2.0, [] { return false; });
  nudger.join();
  EXPECT_LT(SecondsSince(start), 1.0);
  EXPECT_GE(SecondsSince(start), 0.015) << "it should have waited for the nudge";
  // A nudge before the wait (after the last Drain): no wait at all.
  handoff.Nudge();
  start = MonotonicNowNs();
  handoff.WaitForArrival(2.0, [] { return false; });
  EXPECT_LT(SecondsSince(start), 0.5);
  // Nothing new, but the condition holds: no wait either.
  handoff.Drain([](const DeviceSample&) {});
  start = MonotonicNowNs();
  handoff.WaitForArrival(2.0, [] { return true; });
  EXPECT_LT(SecondsSince(start), 0.5);
  // Nothing new and no condition: the timeout.
  start = MonotonicNowNs();
  handoff.WaitForArrival(0.05, [] { return false; });
  EXPECT_GE(SecondsSince(start), 0.04);
}

// ---- RegionHandover -----------------------------------------------------------------------------

// What the handshake hands back and forth: plain data, owned by one thread at a time.
struct PlainRegions {
  std::int64_t steps = 0;       // the primary's writes
  std::int64_t installed = -1;  // the supervisor's
};

TEST(RegionHandover, ThePrimaryLeavesTheRegionsAloneFromItsAcknowledgementUntilTheirRelease) {
  constexpr int kReplacements = 40;
  constexpr std::int64_t kPeriodNs = 200'000;
  RegionHandover handover;
  PlainRegions regions;
  const std::int64_t origin = MonotonicNowNs();
  handover.Reset(RegionRestart::kFromRest, origin);
  std::atomic<bool> stop{false};
  // What the primary saw, written by it only and read after it is joined.
  std::vector<RegionRestart> restarts;
  std::vector<std::int64_t> installed_seen;
  std::vector<bool> holds_seen;
  std::int64_t early_periods = 0;  // kOurs before the release the supervisor resumed at
  std::atomic<std::int64_t> resume_at{origin};
  std::atomic<int> handed_back{0};  // the times the primary has had the regions back
  std::thread primary([&] {
    bool was_ours = false;
    for (std::int64_t k = 0; !stop.load(); ++k) {
      const std::int64_t release = origin + k * kPeriodNs;
      SleepUntilMonotonicNs(release);
      bool pause_began = false;
      const RegionHandover::Period period = handover.Check(release, &pause_began);
      if (pause_began) holds_seen.push_back(handover.hold_force());
      const bool ours = period == RegionHandover::Period::kOurs;
      if (ours && !was_ours) {
        restarts.push_back(handover.TakeRestart());
        installed_seen.push_back(regions.installed);
        if (release < resume_at.load()) ++early_periods;
        handed_back.fetch_add(1);
      }
      if (ours) ++regions.steps;
      was_ours = ours;
    }
  });
  int stepped_while_paused = 0;
  for (int r = 0; r < kReplacements; ++r) {
    // Each replacement after the primary has had the regions back (a thread descheduled for a
    // whole resume would see the next pause first: the protocol allows it, this test counts
    // every hand-back), then a few of its periods.
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (handed_back.load() < r + 1 && std::chrono::steady_clock::now() < deadline) {
      std::this_thread::sleep_for(microseconds(50));
    }
    if (handed_back.load() < r + 1) {
      ADD_FAILURE() << "the primary never had the regions back after replacement " << r;
      break;
    }
    std::this_thread::sleep_for(milliseconds(2));
    handover.RequestPause(r % 2 == 1);
    while (!handover.Acknowledged()) std::this_thread::sleep_for(microseconds(50));
    // The regions are the supervisor's now: the primary must not step them.
    const std::int64_t steps = regions.steps;
    std::this_thread::sleep_for(microseconds(3 * kPeriodNs / 1000));
    if (regions.steps != steps) ++stepped_while_paused;
    regions.installed = r;
    const std::int64_t at = MonotonicNowNs() + 1'000'000;
    resume_at.store(at);
    handover.Resume(r % 3 == 0 ? RegionRestart::kCarryingMotion : RegionRestart::kKeepingContact,
                    at);
  }
  // The last hand-back too, then a few periods.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (handed_back.load() < kReplacements + 1 && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(microseconds(50));
  }
  std::this_thread::sleep_for(milliseconds(2));
  stop = true;
  primary.join();
  EXPECT_EQ(stepped_while_paused, 0);
  EXPECT_EQ(early_periods, 0) << "new regions stepped before their first release";
  ASSERT_EQ(restarts.size(), static_cast<size_t>(kReplacements) + 1);
  EXPECT_EQ(restarts[0], RegionRestart::kFromRest);
  EXPECT_EQ(installed_seen[0], -1);
  ASSERT_EQ(holds_seen.size(), static_cast<size_t>(kReplacements)) << "one first period a pause";
  for (int r = 0; r < kReplacements; ++r) {
    EXPECT_EQ(restarts[r + 1],
              r % 3 == 0 ? RegionRestart::kCarryingMotion : RegionRestart::kKeepingContact);
    EXPECT_EQ(installed_seen[r + 1], r) << "the primary must see the regions installed";
    EXPECT_EQ(holds_seen[r], r % 2 == 1);
  }
  EXPECT_EQ(handover.TakeRestart(), RegionRestart::kNone) << "a restart is applied once";
}

TEST(RegionHandover, AWithdrawnPauseLeavesTheRegionsToThePrimary) {
  RegionHandover handover;
  handover.Reset(RegionRestart::kNone, 0);
  bool began = false;
  EXPECT_EQ(handover.Check(10, &began), RegionHandover::Period::kOurs);
  handover.RequestPause(false);
  EXPECT_TRUE(handover.pause_requested());
  handover.Withdraw();
  EXPECT_EQ(handover.Check(11, &began), RegionHandover::Period::kOurs);
  EXPECT_FALSE(began);
  handover.RequestPause(false);
  EXPECT_EQ(handover.Check(12, &began), RegionHandover::Period::kPaused);
  EXPECT_TRUE(began);
  EXPECT_EQ(handover.Check(13, &began), RegionHandover::Period::kPaused);
  EXPECT_FALSE(began) << "only a pause's first period begins it";
  handover.Resume(RegionRestart::kFromRest, 20);
  EXPECT_EQ(handover.Check(19, &began), RegionHandover::Period::kWaiting);
  EXPECT_EQ(handover.unapplied_restart(), RegionRestart::kFromRest);
  EXPECT_EQ(handover.Check(20, &began), RegionHandover::Period::kOurs);
}

// ---- SecondaryParking ---------------------------------------------------------------------------

TEST(SecondaryParking, SecondariesParkOnlyOnceAllWereFoundAtRestAndEveryWakeReleasesThem) {
  constexpr int kSecondaries = 3;
  constexpr int kSleeps = 25;
  SecondaryParking<4> parking;
  std::array<std::int64_t, kSecondaries + 1> steps{};  // plain: each secondary's own state
  std::array<std::atomic<bool>, kSecondaries + 1> at_rest{};
  std::array<std::int64_t, kSecondaries + 1> woke_at{};  // plain: the last origin each saw
  std::array<std::atomic<bool>, kSecondaries + 1> stepped_since_wake{};
  std::atomic<bool> stop{false};
  std::vector<std::thread> secondaries;
  for (int a = 1; a <= kSecondaries; ++a) {
    secondaries.emplace_back([&, a] {
      while (!stop.load()) {
        const std::uint32_t generation = parking.generation();
        if (!parking.MayStep(a, [&] { return at_rest[a].load(); })) {
          woke_at[a] = parking.WaitForWake(generation, stop, 1.0);
          continue;
        }
        ++steps[a];
        stepped_since_wake[a] = true;
        std::this_thread::sleep_for(microseconds(200));
      }
    });
  }
  auto wait_for = [](auto condition) {
    const std::int64_t give_up = MonotonicNowNs() + 5'000'000'000;
    while (!condition()) {
      if (MonotonicNowNs() > give_up) return false;
      std::this_thread::sleep_for(microseconds(100));
    }
    return true;
  };
  int stepped_while_parked = 0, carried_stale_finding = 0;
  for (int s = 0; s < kSleeps; ++s) {
    // A finding from a watch that a touch closed does not count in the next one.
    for (auto& flag : at_rest) flag = true;
    parking.StartWatch();
    ASSERT_TRUE(wait_for([&] { return parking.AllAtRest(kSecondaries); }));
    parking.StopWatch();
    at_rest[2] = false;
    parking.StartWatch();
    std::this_thread::sleep_for(milliseconds(2));
    if (parking.AllAtRest(kSecondaries)) ++carried_stale_finding;
    at_rest[2] = true;
    ASSERT_TRUE(wait_for([&] { return parking.AllAtRest(kSecondaries); }));
    parking.Park();
    ASSERT_TRUE(wait_for([&] { return parking.AllParked(kSecondaries); }));
    parking.StopWatch();
    // Parked: their states are the primary's (it resets them), and nothing steps them.
    for (auto& count : steps) count = 0;
    std::this_thread::sleep_for(milliseconds(2));
    for (int a = 1; a <= kSecondaries; ++a) stepped_while_parked += steps[a] != 0;
    for (auto& flag : stepped_since_wake) flag = false;
    parking.Wake(1000 + s);
    ASSERT_TRUE(wait_for([&] { return !parking.AllParked(kSecondaries); }));
    // They step again: each of them, however long the machine takes to run them.
    EXPECT_TRUE(wait_for([&] {
      return std::all_of(stepped_since_wake.begin() + 1, stepped_since_wake.end(),
                         [](const std::atomic<bool>& stepped) { return stepped.load(); });
    })) << "a secondary did not step after wake "
        << s;
  }
  stop = true;
  parking.WakeAll();
  for (std::thread& thread : secondaries) thread.join();
  EXPECT_EQ(stepped_while_parked, 0);
  EXPECT_EQ(carried_stale_finding, 0);
  for (int a = 1; a <= kSecondaries; ++a) {
    EXPECT_GT(steps[a], 0) << "region " << a << " should step again after the last wake";
    EXPECT_EQ(woke_at[a], 1000 + kSleeps - 1) << "region " << a << " should restart at its origin";
  }
}

// ---- A secondary's sleep, asked to stop
// ----------------------------------------------------------

// A secondary thread sleeping until a release far ahead comes out within a slice of being asked to
// stop (a reconfiguration joins it: with a plain sleep, it would wait the whole sleep), and one
// not asked wakes at its release, not before.
TEST(SecondarySleep, AThreadAskedToStopLeavesASleepFarAheadWithinASlice) {
  std::atomic<bool> stop{false};
  std::atomic<bool> woke_normally{true};
  const std::int64_t start = MonotonicNowNs();
  std::thread sleeper([&] {
    woke_normally = SleepUntilMonotonicNsOrStop(start + 5'000'000'000, stop, 10'000'000);
  });
  std::this_thread::sleep_for(milliseconds(50));
  const std::int64_t asked = MonotonicNowNs();
  stop = true;
  sleeper.join();
  const double after_s = SecondsSince(asked);
  EXPECT_FALSE(woke_normally);
  EXPECT_LT(after_s, 1.0) << "held by the sleep after the stop";
  std::printf("asked to stop 50 ms into a 5 s sleep: out %.1f ms later\n", 1e3 * after_s);

  stop = false;
  const std::int64_t wake = MonotonicNowNs() + 35'000'000;  // three slices and a half
  EXPECT_TRUE(SleepUntilMonotonicNsOrStop(wake, stop, 10'000'000));
  EXPECT_GE(MonotonicNowNs(), wake);
}

// ---- LoopCounters, on a running loop ------------------------------------------------------------

// Every period a counter counts is an answer flagged for it, and the other way round: the counts
// the status message reports are the answers the device got.
TEST(LoopCounters, EveryCountedPeriodIsAFlaggedAnswer) {
  Scene scene;
  scene.adaptivity.primary_size = 3;
  HapticLoop::Options options;
  options.port.max_force_n = 0.3;  // the press exceeds it: periods limited
  options.sleep_at_rest = false;
  HapticLoop loop(scene, options);
  loop.Start();
  const double edge = scene.mesh.edge_m;
  std::vector<ForceRecord> forces = testing::PlayDevice(loop, 600, [&](int n) {
    return std::array<double, 3>{edge / 2, edge / 2, -0.002 + 0.006 * std::min(1.0, n / 300.0)};
  });
  // No input: stale periods, once the input is older than stale_after_s (50 ms), waited for by
  // count.
  testing::PollUntil([&] { return loop.stale_periods() >= 80; });
  loop.Stop();
  ForceRecord record;
  while (loop.forces().Pop(&record)) forces.push_back(record);
  ASSERT_EQ(loop.forces().dropped(), 0u);
  std::int64_t stale = 0, limited = 0, dissipating = 0, contact = 0;
  for (const ForceRecord& f : forces) {
    stale += (f.flags & force_flags::kInputStale) != 0 && f.seq >= 0;
    limited += (f.flags & force_flags::kForceLimited) != 0;
    dissipating += (f.flags & force_flags::kPortDissipating) != 0;
    contact += (f.flags & force_flags::kInContact) != 0;
  }
  EXPECT_GT(stale, 50);
  EXPECT_GT(limited, 50);
  EXPECT_GT(contact, 100);
  EXPECT_EQ(loop.stale_periods(), stale);
  EXPECT_EQ(loop.limited_periods(), limited);
  // An ordinary press on the default tissue is passive as the loop renders it: the controller
  // stays idle here, and both are 0. Passivity.ADissipatingPeriodIsFlaggedCountedAndItsEnergy…
  // (tests/daemon/engagement_test.cpp) makes it act and checks its count.
  EXPECT_EQ(loop.dissipating_periods(), dissipating);
  EXPECT_GT(loop.last_contact_ns(), 0);
}

}  // namespace
}  // namespace hapticsim
