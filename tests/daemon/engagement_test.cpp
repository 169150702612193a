// Every way back into contact ramps from zero: a new device session with the tool already inside,
// input back after a 100 ms or 1 s gap at another depth, a re-arm after a fault, and new regions
// while the tool presses. Each is played through hapticsimd's real primary period (contact
// tracker, regions, port guard) on one thread, period by period; the force sent must never step
// by more than 0.1 N between periods, never pull the tool into the surface, and come back to the
// tissue's force afterwards (a guard that only zeroes the force would fail that).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <optional>
#include <vector>

#include "core/error.hpp"
#include "daemon/haptic_loop.hpp"
#include "tests/support/play_device.hpp"

namespace hapticsim {
namespace {

constexpr double kMaxStep_n = 0.1;

// The device's tip depth (z, the front face's middle) in period n, or none: nothing sent.
using Depth = std::function<std::optional<double>(int)>;

struct Played {
  std::vector<double> force_z;      // sent, one per period
  std::vector<double> simulated_z;  // the simulation's (the black box's), one per period
  std::vector<std::int32_t> flags;
  double largest_step_n = 0;
  double most_attractive_n = 0;  // the largest +z force (pulling the tool in); 0 is right
};

// hapticsimd's threads played on this one (testing::PlayPeriodInVirtualTime): each period the
// input that arrived at its release (when the device sent one), then the secondaries and the
// primary period. `before(n)` runs first (a supervisor).
Played Play(
    HapticLoop& loop, const Depth& depth, int periods,
    const std::function<void(int)>& before = [](int) {}, std::int64_t seq_origin = 0) {
  Played played;
  static std::int64_t release = 1'000'000'000;  // one clock across the plays of a test
  ForceRecord record;
  double last = 0;
  for (int n = 0; n < periods; ++n, release += 1'000'000) {
    before(n);
    std::optional<DeviceSample> input;
    if (const std::optional<double> z = depth(n)) {
      input = DeviceSample{seq_origin + n, release, {0.125, 0.125, *z}, false};
    }
    testing::PlayPeriodInVirtualTime(loop, release, input);
    BlackBoxRecord box;
    while (loop.black_box().Pop(&box)) played.simulated_z.push_back(box.raw_force_n[2]);
    while (loop.forces().Pop(&record)) {
      const double z = record.force_n[2];
      played.largest_step_n = std::max(played.largest_step_n, std::abs(z - last));
      played.most_attractive_n = std::max(played.most_attractive_n, z);
      played.force_z.push_back(z);
      played.flags.push_back(record.flags);
      last = z;
    }
  }
  return played;
}

Scene DefaultScene() {
  Scene scene;
  scene.adaptivity.primary_size = 3;
  scene.adaptivity.secondary_lod = 2;
  scene.adaptivity.secondary_rate_hz = 1000;
  return scene;
}

// Above the surface for 50 ms, then in to `depth` at 10 mm/s and held.
Depth PressTo(double depth_m) {
  return [depth_m](int n) -> std::optional<double> {
    if (n < 50) return -0.002;
    return std::min(depth_m, 1e-5 * (n - 50));
  };
}

// The force a tool held at `depth_m` settles to, pressed in smoothly (the reference for "the
// force came back").
double SettledForce(double depth_m) {
  HapticLoop loop(DefaultScene(), HapticLoop::Options{});
  return Play(loop, PressTo(depth_m), 2500).force_z.back();
}

void ExpectSmooth(const Played& played, const std::string& what) {
  EXPECT_LE(played.largest_step_n, kMaxStep_n) << what;
  EXPECT_LE(played.most_attractive_n, 1e-12) << what << ": a force pulling the tool in";
}

// On a quiet machine the guard leaves the tissue's force alone: the paper's press (1 cm, 1 Hz, from
// 2 mm above) sends exactly the simulated force in every period the guard did not flag, and the
// only periods it flags are those where the retracting tool would be pulled into the surface.
TEST(QuietPress, TheForceSentIsTheSimulatedForceWhereverTheGuardDidNotAct) {
  HapticLoop loop(DefaultScene(), HapticLoop::Options{});
  const double pi = 3.141592653589793;
  const Played played = Play(
      loop,
      [&](int n) -> std::optional<double> {
        return -0.002 + 0.012 * (1 - std::cos(2 * pi * n / 1000.0)) / 2;
      },
      1000);
  ASSERT_EQ(played.force_z.size(), played.simulated_z.size());
  int limited = 0, pulling = 0;
  double peak = 0, simulated_peak = 0, largest_pull = 0;
  for (size_t n = 0; n < played.force_z.size(); ++n) {
    const bool acted =
        played.flags[n] & (force_flags::kForceLimited | force_flags::kPortDissipating);
    const bool contact = played.flags[n] & force_flags::kInContact;
    if (contact) simulated_peak = std::max(simulated_peak, -played.simulated_z[n]);
    peak = std::max(peak, -played.force_z[n]);
    if (!acted && contact) {
      EXPECT_EQ(played.force_z[n], played.simulated_z[n]) << n;
    }
    if (acted) {
      ++limited;
      pulling += played.simulated_z[n] > 0;  // the tissue would pull the tool in: cut to zero
      largest_pull = std::max(largest_pull, played.simulated_z[n]);
      EXPECT_EQ(played.force_z[n], 0.0) << n;
    }
  }
  EXPECT_EQ(limited, pulling);
  EXPECT_EQ(peak, simulated_peak);  // about 1.5 N
  EXPECT_GT(peak, 1.3);
  ExpectSmooth(played, "quiet press");
  RecordProperty("periods_cut_as_pulling", limited);
  RecordProperty("largest_pull_mN", static_cast<int>(std::lround(largest_pull * 1e3)));
}

class StaleGap : public ::testing::TestWithParam<int> {};

TEST_P(StaleGap, InputBackAtAnotherDepthRampsFromZeroAndTheForceComesBack) {
  const int gap = GetParam();  // periods without input
  HapticLoop loop(DefaultScene(), HapticLoop::Options{});
  // Pressed to 5 mm and held; silent for the gap; back 8 mm in (the hand moved meanwhile).
  const int silent_from = 1000, back_at = silent_from + gap;
  const Played played = Play(
      loop,
      [&](int n) -> std::optional<double> {
        if (n >= silent_from && n < back_at) return std::nullopt;
        return n < back_at ? PressTo(0.005)(n) : 0.008;
      },
      back_at + 1500);
  ExpectSmooth(played, "gap of " + std::to_string(gap) + " ms");
  const bool stale_seen = std::any_of(played.flags.begin(), played.flags.end(),
                                      [](std::int32_t f) { return f & force_flags::kInputStale; });
  EXPECT_TRUE(stale_seen);
  EXPECT_NEAR(played.force_z.back(), SettledForce(0.008), 0.02 * std::abs(SettledForce(0.008)));
  EXPECT_LT(played.force_z.back(), -0.5);  // 8 mm in pushes back
}

INSTANTIATE_TEST_SUITE_P(Gaps, StaleGap, ::testing::Values(100, 1000));

TEST(Engagement, ANewSessionWithTheToolInsideRampsInFromZero) {
  HapticLoop loop(DefaultScene(), HapticLoop::Options{});
  // A first session touches and leaves.
  Play(
      loop, [](int n) -> std::optional<double> { return n < 300 ? PressTo(0.002)(n) : -0.002; },
      600);
  // 0.5 s of silence, then a new driver (its seq from 0 again) with the tool 1 cm in.
  Play(
      loop, [](int) -> std::optional<double> { return std::nullopt; }, 500);
  const Played played = Play(
      loop, [](int) -> std::optional<double> { return 0.01; }, 2000, [](int) {}, 0);
  ExpectSmooth(played, "new session at 1 cm");
  EXPECT_NEAR(played.force_z.back(), SettledForce(0.01), 0.02 * std::abs(SettledForce(0.01)));
}

TEST(Engagement, AFaultReArmsOnlyOutOfContactFromRestAndThenRampsIn) {
  HapticLoop::Options options;
  options.port.max_force_n = 0.5;
  options.port.fault_force_n = 0.6;  // a 1 cm press gives about 1.3 N: a fault on the way in
  HapticLoop loop(DefaultScene(), options);
  bool restarted = false;
  Played in = Play(loop, PressTo(0.01), 1500, [&](int) {
    // The supervisor: on the fault, restart the regions from rest (as hapticsimd does).
    if (loop.force_faults() > 0 && !restarted) {
      loop.Reconfigure(DefaultScene());
      restarted = true;
    }
  });
  ExpectSmooth(in, "fault");
  ASSERT_EQ(loop.force_faults(), 1);
  EXPECT_EQ(loop.runaways(), 0) << "a fault whose state the energy balance allows is no runaway";
  EXPECT_TRUE(loop.fault_latched());
  EXPECT_EQ(in.force_z.back(), 0.0);  // latched: zero, though the tool still presses
  EXPECT_EQ(loop.rearms(), 0);
  // Out of the object: re-armed. In again to 3 mm (about 0.4 N): rendered.
  Played again = Play(loop, PressTo(0.003), 2500);
  ExpectSmooth(again, "re-armed");
  EXPECT_EQ(loop.rearms(), 1);
  EXPECT_FALSE(loop.fault_latched());
  EXPECT_NEAR(again.force_z.back(), SettledForce(0.003), 0.02 * std::abs(SettledForce(0.003)));
}

TEST(Engagement, NewRegionsWhileTheToolPressesRampInFromZero) {
  HapticLoop loop(DefaultScene(), HapticLoop::Options{});
  Scene other = DefaultScene();
  other.adaptivity.primary_size = 2;
  const Played played = Play(loop, PressTo(0.006), 3000, [&](int n) {
    if (n == 1200) loop.Reconfigure(other, HapticLoop::Handover::kRampIn);
  });
  ASSERT_EQ(loop.reconfigurations(), 1);
  ExpectSmooth(played, "reconfiguration in contact");
  // New regions start from rest, the tool's depth ramped in on them: the force sent ramps
  // down (at the engage rate, never stepped) until it meets their own force rising from zero
  // (measured: from 0.59 N to 0.051 N in 10 ms), then rises with it to what the new regions
  // give pressed alone. Carried over instead, it would not have fallen at all.
  ASSERT_LT(played.force_z[1199], -0.5) << "pressing before the new regions";
  const auto after = played.force_z.begin() + 1200;
  const auto lowest = std::max_element(after, after + 200);  // the force nearest zero (z < 0)
  EXPECT_GT(*lowest, 0.15 * played.force_z[1199]) << "the force was not ramped in from near zero";
  HapticLoop alone(other, HapticLoop::Options{});
  const double other_settles = Play(alone, PressTo(0.006), 3000).force_z.back();
  EXPECT_NEAR(played.force_z.back(), other_settles, 0.02 * std::abs(other_settles));
  std::printf(
      "new regions at 6 mm: force %.3f N before, %.4f N at its lowest %td periods later, "
      "%.4f N at the end (those regions pressed alone: %.4f N)\n",
      played.force_z[1199], *lowest, lowest - after, played.force_z.back(), other_settles);
}

// A configuration switched while the tool presses (hapticsimd does this as soon as a better one is
// verified) carries the object's motion over: the force goes on as it was — no ramp from zero, no
// step — and settles where the new configuration's own press settles.
TEST(Engagement, AConfigurationSwitchedInContactCarriesTheForceOnWithoutAStep) {
  const Scene first = DefaultScene();  // r 3, k 2, 1000 Hz
  Scene second = first, third = first;
  second.adaptivity.primary_size = 2, second.adaptivity.secondary_lod = 3;
  second.adaptivity.secondary_rate_hz = 600;
  third.adaptivity.primary_size = 4, third.adaptivity.secondary_rate_hz = 800;
  HapticLoop loop(first, HapticLoop::Options{});
  // In to 1 cm at 10 mm/s from period 50 (at 1 cm from period 1050), switched twice: while
  // pressing in (6 mm) and while held.
  const Played played = Play(loop, PressTo(0.01), 2500, [&](int n) {
    if (n == 650) loop.Reconfigure(second, HapticLoop::Handover::kCarryMotion);
    if (n == 1600) loop.Reconfigure(third, HapticLoop::Handover::kCarryMotion);
  });
  ASSERT_EQ(loop.reconfigurations(), 2);
  ExpectSmooth(played, "switched in contact");
  // The force never drops towards zero across a switch: it is carried, not ramped in again.
  for (int n : {650, 1600}) {
    for (int m = n - 2; m < n + 20; ++m) {
      EXPECT_LT(played.force_z[m], 0.9 * played.force_z[n - 3])
          << "period " << m << ": the force fell back after the switch at " << n;
    }
  }
  HapticLoop alone(third, HapticLoop::Options{});
  const double third_settles = Play(alone, PressTo(0.01), 2500).force_z.back();
  EXPECT_NEAR(played.force_z.back(), third_settles, 0.01 * std::abs(third_settles));
  double across = 0;  // the largest change between periods within 30 ms of a switch
  for (int n : {650, 1600}) {
    for (int m = n - 1; m < n + 30; ++m) {
      across = std::max(across, std::abs(played.force_z[m] - played.force_z[m - 1]));
    }
  }
  EXPECT_LE(across, 0.1);
  std::printf(
      "switched at 6 mm and at 1 cm: largest force change between periods %.4f N across "
      "the switches, %.4f N over the whole press; settled at %.4f N (the last "
      "configuration pressed alone: %.4f N)\n",
      across, played.largest_step_n, played.force_z.back(), third_settles);
}

// A switch while a ramp is still under way (here the engagement of a touch-down found 1 cm deep)
// keeps what is left of that ramp: cut short to the catch-up's 20 ms it stepped the force by
// 0.19–0.20 N.
TEST(Engagement, ASwitchDuringAnEngagementRampKeepsTheRamp) {
  const Scene first = DefaultScene();
  Scene second = first;
  second.adaptivity.primary_size = 2;
  for (int after : {5, 10, 40}) {
    HapticLoop loop(first, HapticLoop::Options{});
    const Played played = Play(
        loop, [](int n) -> std::optional<double> { return n < 50 ? -0.002 : 0.01; }, 600,
        [&](int n) {
          if (n == 50 + after) loop.Reconfigure(second, HapticLoop::Handover::kCarryMotion);
        });
    ExpectSmooth(played, "switched " + std::to_string(after) + " periods into the ramp");
    std::printf("switched %d ms into the engagement ramp: largest force change %.4f N\n", after,
                played.largest_step_n);
    EXPECT_LT(played.force_z.back(), -0.5) << "1 cm in pushes back";
  }
}

// A reset the primary has not applied yet is not undone by a switch that comes before it is: the
// tool must still lift off before it feels force (a fault re-arms only after such a reset).
TEST(Engagement, ASwitchRightAfterAResetLeavesItAReset) {
  HapticLoop loop(DefaultScene(), HapticLoop::Options{});
  Scene second = DefaultScene();
  second.adaptivity.primary_size = 2;
  const Played played = Play(loop, PressTo(0.006), 1200, [&](int n) {
    if (n == 900) {
      loop.Reconfigure(DefaultScene());  // from rest
      loop.Reconfigure(second, HapticLoop::Handover::kCarryMotion);
    }
  });
  // (A reset in contact releases the force at the slew ceiling: the tool is to lift off.)
  EXPECT_EQ(played.force_z.back(), 0.0) << "the reset was undone: force without a lift-off";
  EXPECT_LT(played.force_z[899], -0.5) << "it pressed before the reset";
}

TEST(Engagement, TheMotionIsCarriedOnlyToRegionsAroundTheSameNode) {
  HapticLoop loop(DefaultScene(), HapticLoop::Options{});
  Scene elsewhere = DefaultScene();
  elsewhere.input.contact_node = LatticeIndex{3, 9, 0};
  EXPECT_THROW(loop.Reconfigure(elsewhere, HapticLoop::Handover::kCarryMotion), Error);
  EXPECT_EQ(loop.reconfigurations(), 0);
}

// A primary that takes substeps (a stiff, nearly incompressible material: the secondary at the
// primary's rate needs 2, so both take 2) moves the contact in equal parts across them, from
// where the last period left it — as the offline schedule does. Holding the period's position
// for every substep moved the contact node a whole period's way in the first: a drag of 4m/dt on
// its mass. The same press played through the daemon's primary period and, beside it, through
// regions stepped by hand so (the secondaries a period ahead, as the daemon's threads and
// PlayPeriodInVirtualTime step them, then the substeps) must give the same force to round-off.
TEST(Substeps, APrimaryTakingSubstepsMovesTheContactAsTheOfflineScheduleDoes) {
  Scene scene = DefaultScene();
  scene.material.poisson_ratio = 0.49;
  scene.material.youngs_modulus_pa = 20000;
  scene.material.density_kg_m3 = 800;
  scene.adaptivity.primary_size = 2;
  scene.adaptivity.secondary_lod = 1;
  HapticLoop::Options options;
  options.sleep_at_rest = false;  // the twin below steps every period, as the loop then does
  HapticLoop loop(scene, options);
  ASSERT_EQ(loop.regions().schedule(kPrimaryRegion).substeps, 2) << "the case this test is about";
  AsyncRegions twin(scene);
  std::array<double, 3> from{};
  std::vector<double> twin_z;  // the twin's simulated force of the loop's period n − 1
  const Played played = Play(loop, PressTo(0.006), 700, [&](int n) {
    if (n == 0) return;
    // Where the loop's last period took the contact: the twin steps there as offline runs do,
    // its secondaries a whole period ahead first, as the daemon's threads are.
    const std::array<double, 3> to = loop.regions().primary_contact_m();
    twin.AdvanceSecondariesTo(twin.state_ticks(kPrimaryRegion) +
                              twin.schedule(kPrimaryRegion).substeps *
                                  twin.period_ticks(kPrimaryRegion));
    std::array<double, 3> reaction{};
    for (int q = 1; q <= 2; ++q) {
      std::array<double, 3> at;
      for (int c = 0; c < 3; ++c) at[c] = q == 2 ? to[c] : from[c] + (to[c] - from[c]) * q / 2;
      const std::array<double, 3> r = twin.StepPrimary(at);
      if (q == 1) reaction = r;
    }
    from = to;
    twin_z.push_back(-reaction[2]);
  });
  ASSERT_EQ(played.simulated_z.size(), 700u);
  double largest_difference = 0, largest_force = 0;
  for (size_t n = 0; n < twin_z.size(); ++n) {
    largest_difference = std::max(largest_difference, std::abs(played.simulated_z[n] - twin_z[n]));
    largest_force = std::max(largest_force, std::abs(twin_z[n]));
  }
  EXPECT_GT(largest_force, 0.5) << "a press that shows nothing";
  EXPECT_LT(largest_difference, 1e-9 * largest_force)
      << "the daemon's primary steps its substeps otherwise than the offline schedule";
}

// A tissue twenty times stiffer than the default and undamped, vibrated 1 mm at 20 Hz about 3 mm
// deep: sampled at 1 kHz its contact force changes so much between periods that the force held
// over each (the zero-order hold) would hand the user more energy on the way out than the port
// absorbed on the way in. The passivity controller takes that excess out; every period it acts is
// flagged on the answer and counted, and the energy it took is summed. The force still pushes
// back: lowered along the motion, not zeroed.
TEST(Passivity, ADissipatingPeriodIsFlaggedCountedAndItsEnergySummed) {
  Scene stiff = DefaultScene();
  stiff.material.youngs_modulus_pa *= 20;
  stiff.material.damping_per_s = 0;
  HapticLoop loop(stiff, HapticLoop::Options{});
  const double pi = 3.141592653589793;
  const Played played = Play(
      loop,
      [&](int n) -> std::optional<double> {
        return n < 50 ? -0.002 : 0.003 + 0.001 * std::sin(2 * pi * 20 * n / 1000.0);
      },
      1000);
  std::int64_t flagged = 0;
  double strongest = 0;
  for (size_t n = 0; n < played.flags.size(); ++n) {
    flagged += (played.flags[n] & force_flags::kPortDissipating) != 0;
    strongest = std::min(strongest, played.force_z[n]);
  }
  EXPECT_GT(flagged, 10) << "the passivity controller never acted";
  EXPECT_EQ(loop.dissipating_periods(), flagged);
  EXPECT_GT(loop.port_energy_dissipated_j(), 0.0);
  EXPECT_LT(strongest, -2.0) << "a 4 mm press on this tissue pushes back with several N";
  EXPECT_LE(played.most_attractive_n, 1e-12) << "a force pulling the tool in";
  std::printf(
      "stiff undamped tissue vibrated: %lld periods dissipating, %.3g J taken out; the "
      "force reached %.2f N\n",
      static_cast<long long>(flagged), loop.port_energy_dissipated_j(), strongest);
}

}  // namespace
}  // namespace hapticsim
