// A runaway that reaches the port first. The stress scene of the daemon's runaway test (seed 1,
// case 160: a primary one element deep, the secondary at 700 Hz) grows its energy by about 2× a
// period once it runs away, so the port's divergence fault can latch before the runaway watch has
// seen its kRunawayPeriods periods in a row. Were the fault only a fault, the supervisor would
// restart the same configuration from rest where it ran away — and the watch's count with it. A
// divergence once the state has been above the watch's line in 2 of the watch's last 5 periods
// is counted as the runaway at once, so the supervisor takes the regions to equal rates either
// way; a divergence before that is only a fault.
// Played through hapticsimd's real primary period on one thread, in virtual time.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <optional>

#include "core/regions/stability_stress.hpp"
#include "daemon/haptic_loop.hpp"
#include "tests/support/play_device.hpp"

namespace hapticsim {
namespace {

struct PressRun {
  int fault_period = -1;    // the period whose answer first counted the fault
  int runaway_period = -1;  // the period whose answer first counted the runaway
  RunawayEnergies runaway;
};

// In to 0.3 mm at node (3, 6, 5) of the 7³ stress cube (the face y = edge, pressed along −y):
// 50 periods above the surface, in over 200, then held.
PressRun Press(const HapticLoop::Options& options, int periods) {
  StressRanges ranges;
  ranges.max_nodes = 7;
  const Scene scene = DrawStressCase(1, 160, ranges).scene;
  HapticLoop loop(scene, options);
  const double edge = scene.mesh.edge_m, h = edge / (scene.mesh.nodes - 1);
  PressRun run;
  std::int64_t release = 1'000'000'000;
  for (int n = 0; n < periods; ++n, release += 1'000'000) {
    const double in = n < 50 ? 0 : n < 250 ? (n - 50) / 200.0 : 1;
    const std::array<double, 3> tip{3 * h, edge + 0.002 - 0.0023 * in, 5 * h};
    testing::PlayPeriodInVirtualTime(loop, release, DeviceSample{n, release, tip, false});
    if (run.fault_period < 0 && loop.force_faults() > 0) run.fault_period = n;
    if (run.runaway_period < 0 && loop.runaways() > 0) {
      run.runaway_period = n;
      run.runaway = loop.last_runaway();
    }
  }
  return run;
}

TEST(RunawayAtThePort, ADivergenceWhileTheStateRunsAwayIsCountedAsTheRunawayAtOnce) {
  ASSERT_EQ(DrawStressCase(1, 160, StressRanges{5, 7}).scene.adaptivity.secondary_rate_hz, 700)
      << "the drawn case is no longer the daemon test's scene";
  // The watch alone (a fault limit no state here reaches first): when it counts the runaway.
  HapticLoop::Options watch_only;
  watch_only.port.fault_force_n = 1000;
  const PressRun watched = Press(watch_only, 500);
  ASSERT_GE(watched.runaway_period, 50) << "the scene no longer runs away";
  // A fault limit the state passes within a period or two of crossing the watch's line.
  HapticLoop::Options low_fault;
  low_fault.port.fault_force_n = 30;
  const PressRun faulted = Press(low_fault, watched.runaway_period + 1);
  ASSERT_GE(faulted.fault_period, 0) << "no divergence fault";
  EXPECT_LT(faulted.fault_period, watched.runaway_period)
      << "the fault must come before the watch's own count for this test to mean anything";
  EXPECT_EQ(faulted.runaway_period, faulted.fault_period)
      << "the divergence above the watch's line is the runaway: counted with the fault";
  EXPECT_GT(faulted.runaway.state_j, AsyncRegions::kRunawayFactor * faulted.runaway.allowed_j);
  // A 20 N limit latches before the state has been above the watch's line at all (its ratio to
  // what the balance allows is 31 then, against the line's 32): only a fault, no runaway.
  HapticLoop::Options lower_fault;
  lower_fault.port.fault_force_n = 20;
  const PressRun early = Press(lower_fault, watched.runaway_period - 3);
  ASSERT_GE(early.fault_period, 0) << "no divergence fault";
  EXPECT_LT(early.fault_period, faulted.fault_period);
  EXPECT_EQ(early.runaway_period, -1) << "counted in period " << early.runaway_period;
  std::printf(
      "runaway at the port: the watch alone counts it in period %d; a 30 N fault limit latches "
      "in period %d and the runaway is counted with it (%.3e J against %.3e J allowed); a 20 N "
      "limit latches in period %d, below the line, and counts none\n",
      watched.runaway_period, faulted.fault_period, faulted.runaway.state_j,
      faulted.runaway.allowed_j, early.fault_period);
}

}  // namespace
}  // namespace hapticsim
