// The tip the primary drives, from device inputs that arrive with jitter: on the device's own
// timeline, one device period back, whatever the latency of each input.
#include "daemon/input_resampler.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

namespace hapticsim {
namespace {

constexpr std::int64_t kT = 1'000'000;  // device period and our period, ns
constexpr double kMaxAheadS = 3e-3;

// A 10 mm/s press along z that starts at seq 0.
std::array<double, 3> Press(double device_ns) { return {0.1, 0.1, 1e-2 * device_ns * 1e-9}; }

TEST(InputResampler, FollowsALinearMotionExactlyWhateverEachInputsLatency) {
  InputResampler tip(kT * 1e-9, kMaxAheadS);
  std::mt19937 random(7);
  std::uniform_real_distribution<double> quick(40e3, 60e3), late(300e3, 900e3);  // latency, ns
  const std::int64_t origin = 5'000'000'000;
  // Inputs with their arrival times; each of our releases (k · T + 0.3 T) takes those arrived.
  std::vector<std::pair<std::int64_t, std::int64_t>> arrivals;  // (received, seq)
  for (std::int64_t s = 0; s < 2000; ++s) {
    // Every third input is late by most of a period, every 50th by two periods more: a driver
    // thread woken late. (An input overtaken by a newer one is lost.)
    double latency = s % 3 == 1 ? late(random) : quick(random);
    if (s % 50 == 25) latency += 2.0 * kT;
    arrivals.emplace_back(origin + s * kT + std::llround(latency), s);
  }
  std::sort(arrivals.begin(), arrivals.end());
  size_t next = 0;
  std::int64_t newest = -1;
  double worst_m = 0;
  for (std::int64_t k = 2; k < 2000; ++k) {
    const std::int64_t release = origin + k * kT + 300'000;
    while (next < arrivals.size() && arrivals[next].first <= release) {
      const std::int64_t s = arrivals[next].second;
      if (s > newest) {
        tip.Add(s, arrivals[next].first, Press(static_cast<double>(s * kT)));
        newest = s;
      }
      ++next;
    }
    if (k < 20) continue;
    // The quickest inputs take 40 to 60 µs: the release maps to device time release − 40 to 60
    // µs, and the tip is one period behind that.
    const std::array<double, 3> want = Press(static_cast<double>(release - origin - 50'000 - kT));
    worst_m = std::max(worst_m, std::abs(tip.TipAt(release)[2] - want[2]));
  }
  // 10 µs either way of 10 mm/s: 0.1 µm. Taking the newest input instead is off by up to a
  // period: 10 µm.
  EXPECT_LT(worst_m, 1e-2 * 10.5e-6) << "the tip is not the device's at a constant delay";
  std::printf("largest distance from the device's tip one period back: %.3f µm\n", worst_m * 1e6);
}

TEST(InputResampler, ADriverFivePerCentSlowIsFollowedAtItsPaceWithoutOvershoot) {
  // A driver that sleeps 1 ms between inputs: 1.05 ms per seq on our clock. It hovers 2 mm above
  // the surface, then touches it at once (a jump of 2 mm in one input) and presses at 10 mm/s.
  InputResampler tip(kT * 1e-9, kMaxAheadS);
  auto z = [](std::int64_t s) { return s < 50 ? -0.002 : 1e-5 * static_cast<double>(s - 50); };
  double deepest_beyond_m = 0, worst_step_m = 0, previous = -0.002;
  std::int64_t s = 0;
  for (std::int64_t k = 0; k < 1000; ++k) {  // our releases, 1 ms apart
    const std::int64_t release = k * kT;
    while (static_cast<double>(s) * 1.05e6 + 50e3 <= static_cast<double>(release)) {
      tip.Add(s, std::llround(static_cast<double>(s) * 1.05e6 + 50e3), {0.1, 0.1, z(s)});
      ++s;
    }
    if (s < 2) continue;
    const double at = tip.TipAt(release)[2];
    deepest_beyond_m = std::max(deepest_beyond_m, at - z(s - 1));  // past the newest input
    if (k > 100) worst_step_m = std::max(worst_step_m, std::abs(at - previous));
    previous = at;
  }
  EXPECT_LE(deepest_beyond_m, 1e-12) << "the tip went past where the device has been";
  // Pressing at 10 mm/s: 10 µm per period, at the device's pace 9.5 µm; never more than that.
  EXPECT_LT(worst_step_m, 1.01e-5);
}

TEST(InputResampler, ABurstOfInputsAfterAStallIsPlacedOnTheTimeline) {
  // The device and the primary held up together for 6 ms (a loaded machine): the device sends its
  // missed inputs back to back, and the primary runs its missed periods back to back after they
  // arrived. Each of those periods still gets the tip of its own release time — not the oldest
  // input a short history still holds (measured: a 4-period burst put the tip 34 µm ahead in one
  // period, a 0.11 N spike on a 1.4 N press, then held it for three).
  InputResampler tip(kT * 1e-9, kMaxAheadS);
  const std::int64_t latency = 50'000;
  for (std::int64_t s = 0; s < 100; ++s) {
    tip.Add(s, s * kT + latency, Press(static_cast<double>(s * kT)));
  }
  const std::int64_t burst_at = 106 * kT + 200'000;  // seq 100 … 106 arrive now
  for (std::int64_t s = 100; s <= 106; ++s) {
    tip.Add(s, burst_at, Press(static_cast<double>(s * kT)));
  }
  for (std::int64_t k = 100; k <= 107; ++k) {  // the primary's releases, k · T, run late
    const double want = Press(static_cast<double>(k * kT - latency - kT))[2];
    EXPECT_NEAR(tip.TipAt(k * kT)[2], want, 1e-12) << "release " << k;
  }
}

TEST(InputResampler, AHugeSeqKeepsTheTipFinite) {
  // Seqs far from zero (a driver that counts from its epoch, or a hostile sender): the device
  // time s · T in doubles would lose whole periods (found: two consecutive seqs near 2⁶² gave
  // one device time and a NaN tip). The timeline counts from its first seq instead.
  for (const std::int64_t start : {std::int64_t{1} << 53, std::int64_t{1} << 62,
                                   std::numeric_limits<std::int64_t>::max() - 100}) {
    InputResampler tip(kT * 1e-9, kMaxAheadS);
    for (std::int64_t k = 0; k < 50; ++k) {
      tip.Add(start + k, k * kT, Press(static_cast<double>(k * kT)));
      const std::array<double, 3> at = tip.TipAt(k * kT + kT / 2);
      ASSERT_TRUE(std::isfinite(at[2])) << start << " + " << k;
    }
    EXPECT_NEAR(tip.TipAt(50 * kT)[2], Press(49.0 * kT)[2], 1e-12) << start;
  }
  // From a small seq to 2⁵³ (the guard's largest) and on: a new timeline, the tip exact on it.
  {
    InputResampler leap(kT * 1e-9, kMaxAheadS);
    leap.Add(1, 0, {0.1, 0.1, 0.0});
    leap.Add(2, kT, {0.1, 0.1, 0.0});
    const std::int64_t big = std::int64_t{1} << 53;
    for (std::int64_t k = 0; k < 50; ++k) {
      leap.Add(big - 50 + k, (10 + k) * kT, Press(static_cast<double>(k * kT)));
    }
    EXPECT_NEAR(leap.TipAt(60 * kT)[2], Press(49.0 * kT)[2], 1e-12);
  }
  // A seq that leaps ahead by more than a double holds exactly starts a new timeline too.
  InputResampler tip(kT * 1e-9, kMaxAheadS);
  tip.Add(1, 0, {0.1, 0.1, 0.001});
  tip.Add(2, kT, {0.1, 0.1, 0.002});
  tip.Add(std::numeric_limits<std::int64_t>::max(), 2 * kT, {0.1, 0.1, 0.003});
  tip.Add(std::numeric_limits<std::int64_t>::min(), 3 * kT, {0.1, 0.1, 0.004});
  EXPECT_TRUE(std::isfinite(tip.TipAt(4 * kT)[2]));
}

TEST(InputResampler, ContinuesAtMostMaxAheadPastTheNewestInputThenHolds) {
  InputResampler tip(kT * 1e-9, kMaxAheadS);
  for (std::int64_t s = 0; s < 10; ++s) tip.Add(s, s * kT, Press(static_cast<double>(s * kT)));
  // Inputs stop at seq 9 (device time 9 ms); a release at 11 ms looks at 10 ms: continued.
  EXPECT_NEAR(tip.TipAt(11 * kT)[2], Press(10.0 * kT)[2], 1e-12);
  // Far later: 3 ms past the newest input and no further.
  EXPECT_NEAR(tip.TipAt(100 * kT)[2], Press(12.0 * kT)[2], 1e-12);
}

TEST(InputResampler, ARestartedDriverStartsAfreshAndALongPauseMovesTheEnvelope) {
  InputResampler tip(kT * 1e-9, kMaxAheadS);
  EXPECT_FALSE(tip.has_input());
  for (std::int64_t s = 100; s < 200; ++s) tip.Add(s, s * kT, Press(static_cast<double>(s * kT)));
  EXPECT_TRUE(tip.has_input());
  // The driver restarts from seq 0 at a new position: only its own inputs count.
  const std::int64_t at = 300 * kT;
  tip.Add(0, at, {0.2, 0.2, 0.001});
  EXPECT_EQ(tip.TipAt(at + kT)[2], 0.001) << "one input of the new driver: its position, held";
  tip.Add(1, at + kT, {0.2, 0.2, 0.002});
  EXPECT_NEAR(tip.TipAt(at + 2 * kT)[2], 0.002, 1e-12);
  // A driver that paused for 0.1 s without counting the periods: the latency jumps by 0.1 s and
  // the envelope follows at once rather than predicting 0.1 s ahead of the last input.
  tip.Add(2, at + 102 * kT, {0.2, 0.2, 0.003});
  tip.Add(3, at + 103 * kT, {0.2, 0.2, 0.004});
  EXPECT_NEAR(tip.TipAt(at + 104 * kT)[2], 0.004, 1e-12);
}

TEST(InputResampler, FollowsADeviceClockThatRunsSlowerThanOurs) {
  // The device's crystal 200 ppm slow: its inputs arrive later and later on our clock; the tip
  // stays one period behind the newest input, for ever.
  InputResampler tip(kT * 1e-9, kMaxAheadS);
  double worst_ns = 0;
  for (std::int64_t s = 0; s < 200'000; ++s) {  // 200 s
    const auto received = static_cast<std::int64_t>(static_cast<double>(s * kT) * 1.0002) + 50'000;
    tip.Add(s, received, Press(static_cast<double>(s * kT)));
    // How far the tip at the input's arrival is behind the input, on the device's timeline.
    const double behind =
        (Press(static_cast<double>(s * kT))[2] - tip.TipAt(received)[2]) / 1e-2 * 1e9;
    if (s > 10) worst_ns = std::max(worst_ns, std::abs(behind - kT));
  }
  // The drift, 0.2 µs per input, is carried forward along the window's trend: exactly, but for
  // rounding to whole nanoseconds. (The window's plain minimum would be 15 × 0.2 µs behind;
  // the minimum of all time, 40 ms after 200 s.)
  EXPECT_LT(worst_ns, 10);
}

}  // namespace
}  // namespace hapticsim
