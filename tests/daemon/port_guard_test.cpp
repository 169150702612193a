// The force-safety layer at the device port on its own: the energy it observes against the work
// done on a moving device, what a passive environment gets (nothing changed) and what an active
// one gets (exactly its excess taken away), the envelope, the ramps and the latched faults.
#include "daemon/port_guard.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace hapticsim {
namespace {

constexpr double kPeriod_s = 1e-3;
constexpr std::int64_t kPeriodNs = 1'000'000;
constexpr double kPi = 3.141592653589793;
using Vec = std::array<double, 3>;

double Norm(const Vec& v) { return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

// Drives the guard with a device moving along z (pressing in is +z, the front face's inward
// normal) and an environment force computed from the device's positions.
struct PortRun {
  double min_energy_j = std::numeric_limits<double>::infinity();
  double work_on_device_j = 0;  // Σ F_sent · Δp: the energy the user received from the port
  double largest_change_n = 0;  // between consecutive forces sent
  int dissipating = 0, limited = 0;
  double largest_difference_n = 0;  // |sent − simulated|
};

template <typename Environment>
PortRun Drive(PortGuard& guard, int periods, double amplitude_m, double frequency_hz,
              Environment environment) {
  PortRun run;
  Vec previous_sent{}, previous_position{};
  for (int n = 0; n < periods; ++n) {
    const double t = n * kPeriod_s;
    // A press: in from the surface and back out, (1 − cos) so it starts at rest.
    const Vec position{0.125, 0.125, amplitude_m * (1 - std::cos(2 * kPi * frequency_hz * t)) / 2};
    PortGuard::Input in;
    in.now_ns = n * kPeriodNs;
    in.simulated_n = environment(position, previous_position, n);
    in.render = true;
    in.engaged = true;
    in.position_m = position;
    in.have_position = true;
    in.inward_normal = {0, 0, 1};
    const PortGuard::Output out = guard.Period(in);
    if (n > 0) {
      for (int c = 0; c < 3; ++c) {
        run.work_on_device_j += previous_sent[c] * (position[c] - previous_position[c]);
      }
    }
    const Vec change{out.force_n[0] - previous_sent[0], out.force_n[1] - previous_sent[1],
                     out.force_n[2] - previous_sent[2]};
    run.largest_change_n = std::max(run.largest_change_n, Norm(change));
    const Vec difference{out.force_n[0] - in.simulated_n[0], out.force_n[1] - in.simulated_n[1],
                         out.force_n[2] - in.simulated_n[2]};
    run.largest_difference_n = std::max(run.largest_difference_n, Norm(difference));
    run.min_energy_j = std::min(run.min_energy_j, guard.port_energy_j());
    run.dissipating += out.dissipating;
    run.limited += out.limited;
    previous_sent = out.force_n;
    previous_position = position;
  }
  return run;
}

// A sampled spring and damper, F = −k x − b ẋ: passive with a zero-order hold when b > kT/2
// (Colgate and Schenkel), here by a factor of 13. Unilateral like tissue: it never pulls (a pull
// would be the guard's to remove, and this environment should need nothing from it).
auto SpringDamper(double k, double b) {
  return [k, b](const Vec& p, const Vec& previous, int n) {
    const double v = n == 0 ? 0.0 : (p[2] - previous[2]) / kPeriod_s;
    return Vec{0, 0, std::min(0.0, -k * p[2] - b * v)};
  };
}

TEST(PortGuard, TheObserverSumsTheWorkTheForceSentDidOnTheDevice) {
  PortGuardSettings settings;
  settings.passivity = false;
  PortGuard guard(settings, kPeriod_s);
  const PortRun run = Drive(guard, 700, 0.01, 1.0, SpringDamper(150, 1.0));
  // E = −Σ F·Δp exactly: the guard's observer against the same sum made here, independently.
  EXPECT_NEAR(guard.port_energy_j(), -run.work_on_device_j, 1e-15);
  EXPECT_GT(guard.port_energy_j(), 0.0);  // pressing in stores energy in the spring
}

TEST(PortGuard, APassiveEnvironmentIsSentUnchanged) {
  PortGuard guard(PortGuardSettings{}, kPeriod_s);
  // A whole 1 cm press at 1 Hz on a 150 N/m tissue (the default scene's 1.5 N peak).
  const PortRun run = Drive(guard, 1000, 0.01, 1.0, SpringDamper(150, 1.0));
  EXPECT_EQ(run.dissipating, 0);
  EXPECT_EQ(run.limited, 0);
  EXPECT_EQ(run.largest_difference_n, 0.0);
  EXPECT_GE(run.min_energy_j, 0.0);
  EXPECT_EQ(guard.dissipated_j(), 0.0);
}

TEST(PortGuard, AnActiveEnvironmentIsMadePassiveByExactlyItsExcess) {
  // A spring with negative damping: it pushes the tool along its motion, and a user holding the
  // tool receives energy from it.
  const auto active = [](const Vec& p, const Vec& previous, int n) {
    const double v = n == 0 ? 0.0 : (p[2] - previous[2]) / kPeriod_s;
    return Vec{0, 0, -150 * p[2] + 20 * v};
  };
  PortGuardSettings off;
  off.passivity = false;
  PortGuard unguarded(off, kPeriod_s);
  const PortRun free = Drive(unguarded, 3000, 0.01, 1.0, active);
  PortGuard guard(PortGuardSettings{}, kPeriod_s);
  const PortRun guarded = Drive(guard, 3000, 0.01, 1.0, active);
  // Unguarded the port hands the user energy (the spring's share comes back each press; the
  // negative damper's accumulates).
  EXPECT_LT(free.min_energy_j, -0.005);
  // Guarded, the observed energy never falls below what one period's misprediction of the
  // motion costs: under 1 % of what the unguarded port gave away.
  EXPECT_GT(guarded.min_energy_j, -0.01 * -free.min_energy_j);
  EXPECT_GT(guarded.dissipating, 100);
  // What it took away is what the negative damper put in: 20 N·s/m · ∫v² dt over 3 presses,
  // 3 · 20 · (π A f)² / 2 = 0.0296 J, less the periods where its push was a pull into the surface
  // (removed as such: unilateral), which this bound leaves room for.
  // The dissipation is measured as the observer measures: the work the controller's correction
  // kept from the user over the motion that followed. A misprediction makes it a little more.
  const double generated_j = 3 * 20 * std::pow(kPi * 0.01 * 1.0, 2) / 2;
  EXPECT_LE(guard.dissipated_j(), 1.1 * generated_j);
  EXPECT_GT(guard.dissipated_j(), 0.8 * generated_j);
  // Within the slew ceiling, whatever the damping asked for.
  EXPECT_LE(guarded.largest_change_n, 0.5 + 1e-12);
}

TEST(PortGuard, ContactIsUnilateralAndTheMagnitudeIsCeiled) {
  PortGuardSettings settings;
  settings.max_force_n = 2.0;
  settings.engage_rate_n_per_ms = 0.5;
  PortGuard guard(settings, kPeriod_s);
  PortGuard::Input in;
  in.render = true;
  in.inward_normal = {0, 0, 1};
  // Pulling the tool into the surface (+z on the user) with a tangential part: only the tangential
  // part is sent.
  in.simulated_n = {0.2, 0, 0.4};
  PortGuard::Output out = guard.Period(in);
  EXPECT_DOUBLE_EQ(out.force_n[0], 0.2);
  EXPECT_DOUBLE_EQ(out.force_n[2], 0.0);
  EXPECT_TRUE(out.limited);
  // Pushing out harder than the device may: ceiled at 2 N, direction kept, reached by the slew.
  in.simulated_n = {0, 3, -4};
  for (int n = 1; n < 20; ++n) {
    in.now_ns = n * kPeriodNs;
    out = guard.Period(in);
  }
  EXPECT_NEAR(Norm(out.force_n), 2.0, 1e-12);
  EXPECT_NEAR(out.force_n[1] / out.force_n[2], -0.75, 1e-12);
  EXPECT_TRUE(out.limited);
}

// Off for a test (hapticsimd --no-port-guard): no unilateral cut, ceiling or slew — the soak then
// sees the coupling's own force — but a divergence still latches a fault.
TEST(PortGuard, OffForATestItSendsTheSimulatedForceAndStillLatchesFaults) {
  PortGuardSettings settings;
  settings.max_force_n = 2.0;
  PortGuard guard(settings, kPeriod_s, PortGuard::Mode::kOffForTests);
  EXPECT_FALSE(guard.guarded());
  PortGuard::Input in;
  in.render = true;
  in.engaged = true;
  in.inward_normal = {0, 0, 1};
  in.simulated_n = {0.02, 0, 0.04};  // within one engage step: no ramp, and a pull is sent
  PortGuard::Output out = guard.Period(in);
  EXPECT_EQ(out.force_n, in.simulated_n);
  EXPECT_FALSE(out.limited);
  in.now_ns = kPeriodNs;
  in.simulated_n = {0, 3, -4};  // 5 N in one period: above the ceiling, ten times the slew
  out = guard.Period(in);
  EXPECT_EQ(out.force_n, in.simulated_n);
  EXPECT_FALSE(out.limited);
  EXPECT_FALSE(out.dissipating);
  in.now_ns = 2 * kPeriodNs;
  in.simulated_n = {0, 0, -2 * settings.fault_force_n};
  out = guard.Period(in);
  EXPECT_EQ(out.new_fault, PortGuard::Fault::kDivergence);
  EXPECT_TRUE(out.latched);
}

TEST(PortGuard, EngagingRampsFromZeroAndReleasingRampsToZero) {
  PortGuardSettings settings;  // 0.05 N per ms
  PortGuard guard(settings, kPeriod_s);
  PortGuard::Input in;
  in.inward_normal = {0, 0, 1};
  in.simulated_n = {0, 0, -1.5};  // a tool found 1 cm deep: 1.5 N at once
  double last = 0, largest_step = 0;
  int periods = 0;
  std::int64_t now = 0;
  auto period = [&](bool render) {
    in.render = render;
    in.now_ns = now += kPeriodNs;
    const double sent = guard.Period(in).force_n[2];
    largest_step = std::max(largest_step, std::abs(sent - last));
    last = sent;
    ++periods;
  };
  in.engaged = true;
  while (last > -1.5 && periods < 1000) period(true);
  EXPECT_LE(largest_step, 0.05 + 1e-12);
  EXPECT_NEAR(periods, 30, 1);  // 1.5 N at 0.05 N per ms
  period(false);  // the input went stale, the tool still in: released by the same ramp
  EXPECT_NEAR(last, -1.45, 1e-12);
  while (last < 0 && periods < 1000) period(false);
  EXPECT_LE(largest_step, 0.05 + 1e-12);
  // Pressing again (a new ramp in), then the tool leaves the object: it is gone, so the release
  // runs faster, at the lift-off rate, 0.1 N per ms (not the slew ceiling's 0.5: no step a hand
  // feels).
  while (last > -1.5 && periods < 1000) period(true);
  in.engaged = false;
  largest_step = 0;
  const int lifted_at = periods;
  while (last < 0 && periods < 1000) period(false);
  EXPECT_EQ(last, 0.0);
  EXPECT_NEAR(largest_step, 0.1, 1e-12);
  EXPECT_NEAR(periods - lifted_at, 15, 1);  // 1.5 N at 0.1 N per ms (16: a rounding's remainder)
  // Above the slew ceiling a lift-off releases at the ceiling.
  PortGuardSettings steep;
  steep.lift_off_rate_n_per_ms = 100;
  EXPECT_EQ(steep.LiftOffRate(), 0.5);
  // A profile whose engage ramp is faster than its lift-off rate releases a lift-off at the ramp.
  PortGuardSettings quick;
  quick.engage_rate_n_per_ms = 0.3;
  PortGuard quick_guard(quick, kPeriod_s);
  PortGuard::Input press = in;
  press.engaged = true;
  press.render = true;
  double sent = 0;
  for (int k = 0; k < 10; ++k, now += kPeriodNs) {
    press.now_ns = now;
    sent = quick_guard.Period(press).force_n[2];
  }
  ASSERT_EQ(sent, -1.5);
  press.engaged = press.render = false;
  press.now_ns = now;
  EXPECT_NEAR(quick_guard.Period(press).force_n[2], -1.2, 1e-12);
  // A normal touch-down starts from almost nothing: no ramp, the simulated force is sent as is.
  in.simulated_n = {0, 0, -0.01};
  period(true);
  EXPECT_DOUBLE_EQ(last, -0.01);
}

TEST(PortGuard, AFaultLatchesReleasesToZeroAndStaysUntilRearmed) {
  PortGuard guard(PortGuardSettings{}, kPeriod_s);
  PortGuard::Input in;
  in.render = true;
  in.inward_normal = {0, 0, 1};
  in.simulated_n = {0, 0, -1.0};
  std::int64_t now = 0;
  PortGuard::Output out;
  for (int n = 0; n < 40; ++n) in.now_ns = now += kPeriodNs, out = guard.Period(in);
  ASSERT_DOUBLE_EQ(out.force_n[2], -1.0);
  in.simulated_n = {0, 0, std::nan("")};
  in.now_ns = now += kPeriodNs;
  out = guard.Period(in);
  EXPECT_EQ(out.new_fault, PortGuard::Fault::kNonFinite);
  EXPECT_TRUE(out.latched);
  EXPECT_NEAR(out.force_n[2], -0.95, 1e-12);  // on its way down, not a step
  // A valid force again does not bring it back: latched.
  in.simulated_n = {0, 0, -1.0};
  for (int n = 0; n < 100; ++n) {
    in.now_ns = now += kPeriodNs;
    out = guard.Period(in);
    EXPECT_EQ(out.new_fault, PortGuard::Fault::kNone);
  }
  EXPECT_EQ(out.force_n[2], 0.0);
  EXPECT_TRUE(guard.latched());
  guard.Rearm();
  in.now_ns = now += kPeriodNs;
  out = guard.Period(in);
  EXPECT_FALSE(out.latched);
  EXPECT_NEAR(out.force_n[2], -0.05, 1e-12);  // re-armed at depth: ramps in from zero
}

TEST(PortGuard, ADivergingForceAndAStalledPrimaryAreFaults) {
  PortGuard guard(PortGuardSettings{}, kPeriod_s);
  PortGuard::Input in;
  in.render = true;
  in.simulated_n = {0, 0, -60};  // above fault_force_n = 50 N
  EXPECT_EQ(guard.Period(in).new_fault, PortGuard::Fault::kDivergence);

  PortGuard stalled(PortGuardSettings{}, kPeriod_s);
  in.simulated_n = {0, 0, -0.01};
  std::int64_t now = kPeriodNs;
  for (int n = 0; n < 5; ++n) in.now_ns = now += kPeriodNs, stalled.Period(in);
  in.now_ns = now += 150 * kPeriodNs;  // late (a loaded desktop), within the 0.2 s watchdog
  EXPECT_EQ(stalled.Period(in).new_fault, PortGuard::Fault::kNone);
  in.now_ns = now += 250 * kPeriodNs;  // 250 ms with the device holding the last force
  EXPECT_EQ(stalled.Period(in).new_fault, PortGuard::Fault::kWatchdog);
  // A force sent and then released to zero: a long gap after is no fault (an idle primary waits
  // for input while the regions sleep).
  PortGuard idle(PortGuardSettings{}, kPeriod_s);
  in.simulated_n = {0, 0, -1.0};
  for (int n = 0; n < 40; ++n) in.now_ns = now += kPeriodNs, idle.Period(in);
  in.render = false;
  PortGuard::Output released;
  for (int n = 0; n < 40; ++n) in.now_ns = now += kPeriodNs, released = idle.Period(in);
  ASSERT_EQ(released.force_n[2], 0.0);
  in.now_ns = now += 2'000 * kPeriodNs;
  EXPECT_EQ(idle.Period(in).new_fault, PortGuard::Fault::kNone);
}

TEST(PortGuard, TheSlewCeilingBoundsEveryChange) {
  PortGuardSettings settings;
  settings.max_force_rate_n_per_ms = 0.2;
  PortGuard guard(settings, kPeriod_s);
  PortGuard::Input in;
  in.render = true;
  in.inward_normal = {0, 0, 1};
  in.simulated_n = {0, 0, -0.04};  // touch-down, within one ramp step
  guard.Period(in);
  double last = -0.04;
  for (int n = 0; n < 20; ++n) {
    in.now_ns = (n + 1) * kPeriodNs;
    in.simulated_n = {0, 0, n % 2 ? -5.0 : 3.0};  // an oscillating simulation
    const PortGuard::Output out = guard.Period(in);
    EXPECT_LE(std::abs(out.force_n[2] - last), 0.2 + 1e-12);
    EXPECT_LE(out.force_n[2], 0.0);  // never pulling into the surface
    last = out.force_n[2];
  }
}

TEST(PortGuard, DampingStaysWithinTheCeilingAndNeverPulls) {
  // A deficit (the port gave more than it took, as an active environment would) with the tool
  // moving fast: the controller's damping is bounded by max_damping, and what it leaves by the
  // ceiling and the surface.
  PortGuardSettings settings;
  settings.max_damping_n_s_per_m = 1000;  // the most the config allows
  PortGuard guard(settings, kPeriod_s);
  PortGuard::Input in;
  in.render = in.engaged = in.have_position = true;
  in.inward_normal = {0, 0, 1};
  double z = 0.0;
  PortGuard::Output out;
  for (int n = 0; n < 200; ++n) {
    in.now_ns = (n + 1) * kPeriodNs;
    z += n < 100 ? 1e-4 : -1e-3;  // in at 0.1 m/s, out at 1 m/s
    in.position_m = {0.1, 0.1, z};
    in.simulated_n = {0.5, 0, n < 100 ? -0.5 : -7.9};  // pushing out hard on the way out
    out = guard.Period(in);
    EXPECT_LE(Norm(out.force_n), settings.max_force_n + 1e-12) << n;
    EXPECT_LE(out.force_n[2], 1e-12) << n;
  }
  EXPECT_GT(guard.dissipated_j(), 0.0);
}

TEST(PortGuard, PeriodsRunBackToBackMoveTheForceByItsRatePerMillisecondOfWallTime) {
  PortGuard guard(PortGuardSettings{}, kPeriod_s);
  PortGuard::Input in;
  in.render = in.engaged = true;
  in.inward_normal = {0, 0, 1};
  in.simulated_n = {0, 0, -0.01};
  in.now_ns = kPeriodNs;
  guard.Period(in);
  // Five missed periods run within 50 µs of each other, the simulation jumping 3 N meanwhile:
  // 0.5 N per ms of wall time allows 0.025 N over those 50 µs, not 2.5 N.
  in.simulated_n = {0, 0, -3.0};
  PortGuard::Output out;
  for (int n = 0; n < 5; ++n) {
    in.now_ns = 10 * kPeriodNs + n * 10'000;
    out = guard.Period(in);
  }
  EXPECT_NEAR(out.force_n[2], -0.01 - 0.5 - 4 * 0.005, 1e-9);  // the first a whole period late
}

}  // namespace
}  // namespace hapticsim
