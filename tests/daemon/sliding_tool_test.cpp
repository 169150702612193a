// hapticsimd's tool that slides (contact.model = "proxy"), played through the real primary period
// (the sliding contact, the regions, the port guard) on one thread, with a supervisor that moves
// the regions whenever the loop asks them to follow the proxy (HapticLoop::contact_following),
// the motion carried. The device draws the offline stroke's own path, so the daemon's force is
// checked against RunRegionStroke on the same scene — and against what the contact promises
// whatever the regions do: once sliding, the lateral force is μ_k times the normal (±5 %);
// without friction there is none; no step over 0.1 N between periods, across the moves too.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <string>
#include <vector>

#include "core/regions/async_regions.hpp"
#include "core/regions/region_stroke_trial.hpp"
#include "core/scene/contact_trajectory.hpp"
#include "core/scene/scene_geometry.hpp"
#include "core/scene/scene_toml.hpp"
#include "daemon/contact_object.hpp"
#include "daemon/haptic_loop.hpp"
#include "daemon/sliding_contact.hpp"
#include "daemon/supervisor.hpp"
#include "tests/support/play_device.hpp"

namespace hapticsim {
namespace {

// The offline stroke of tests/core/region_stroke_test.cpp: 5 mm into the front face's middle,
// then 80 mm along x (the proxy crosses four nodes of 20.8 mm).
Scene Stroke(double static_mu, double kinetic_mu) {
  Scene scene;
  scene.input.waveform = Waveform::kStroke;
  scene.input.amplitude_m = 0.005;
  scene.input.stroke_length_m = 0.08;
  scene.contact.static_friction = static_mu;
  scene.contact.kinetic_friction = kinetic_mu;
  scene.adaptivity.primary_size = 3;
  return scene;
}

struct Served {
  std::vector<std::array<double, 3>> force_n;  // sent to the device, one per period
  std::vector<std::int32_t> flags;             // of each
  int moves = 0;                               // the regions followed the proxy
  double largest_step_n = 0;
};

// The stroke's path (or `tip_at(n)`'s) played as device input, one period each, the regions moved
// (motion carried) before any period the loop asks them to follow; `before(n, loop)` runs first
// (another supervisor's act).
Served Serve(
    const Scene& scene,
    const std::function<void(long, HapticLoop&)>& before = [](long, HapticLoop&) {},
    const std::function<std::array<double, 3>(long)>& tip_at = {}) {
  HapticLoop loop(scene, HapticLoop::Options{});
  const ContactTrajectory path(scene.input);
  const long periods = std::lround(scene.duration_s() / scene.solver.dt_s);
  const RegionConfiguration configuration{scene.adaptivity.primary_size,
                                          scene.adaptivity.secondary_lod,
                                          scene.adaptivity.secondary_rate_hz};
  Served served;
  std::int64_t release = 1'000'000'000;
  for (long n = 0; n <= periods; ++n, release += 1'000'000) {
    before(n, loop);
    if (loop.contact_following() && loop.wanted_contact_node() != loop.centre_node()) {
      loop.Reconfigure(SceneWith(scene, configuration, *loop.wanted_contact_node()),
                       HapticLoop::Handover::kCarryMotion);
      ++served.moves;
    }
    std::array<double, 3> tip = {0.125, 0.125, 0.0};
    const std::array<double, 3> moved = path.DisplacementAt(static_cast<double>(n) * 1e-3);
    for (int c = 0; c < 3; ++c) tip[c] += moved[c];
    if (tip_at) tip = tip_at(n);
    testing::PlayPeriodInVirtualTime(loop, release, DeviceSample{n, release, tip, false});
    ForceRecord record;
    while (loop.forces().Pop(&record)) {
      if (!served.force_n.empty()) {
        const auto& a = served.force_n.back();
        const auto& b = record.force_n;
        served.largest_step_n =
            std::max(served.largest_step_n, std::hypot(b[0] - a[0], b[1] - a[1], b[2] - a[2]));
      }
      served.force_n.push_back(record.force_n);
      served.flags.push_back(record.flags);
    }
  }
  return served;
}

TEST(SlidingTool, TheDaemonServesTheOfflineStrokeAndItsRegionsFollowTheProxy) {
  const Scene scene = Stroke(0.5, 0.4);
  const Served served = Serve(scene);
  const RegionStrokeResult offline = RunRegionStroke(scene);
  ASSERT_EQ(offline.stroke.trial.outcome, TrialOutcome::kCompleted);
  const std::vector<ForceSample>& samples = offline.stroke.trial.samples;
  ASSERT_GE(served.force_n.size(), samples.size());
  EXPECT_EQ(served.moves, static_cast<int>(offline.moves.size()));
  EXPECT_LE(served.largest_step_n, 0.1);
  double error2 = 0, norm2 = 0, worst_ratio = 0;
  int sliding = 0;
  for (std::size_t n = 0; n < samples.size(); ++n) {
    const std::array<double, 3>& f = served.force_n[n];
    for (int c = 0; c < 3; ++c) {
      error2 += std::pow(f[c] - samples[n].feedback_force_n[c], 2);
      norm2 += std::pow(samples[n].feedback_force_n[c], 2);
    }
    const double normal = -f[2], lateral = std::hypot(f[0], f[1]);
    // Coulomb: never more than μ_s × the normal; once sliding (the offline stroke slid in this
    // period and the two before: the daemon may break loose a period later), μ_k × the normal.
    EXPECT_LE(lateral, 1.05 * 0.5 * normal + 1e-6) << "period " << n;
    const auto slid = [&](std::size_t m) { return offline.stroke.proxy[m].sliding; };
    if (n >= 2 && slid(n) && slid(n - 1) && slid(n - 2) && normal > 0.05) {
      ++sliding;
      worst_ratio = std::max(worst_ratio, lateral / normal);
      EXPECT_GE(lateral, 0.95 * 0.4 * normal) << "period " << n;
    }
  }
  const double relative_l2 = std::sqrt(error2 / norm2);
  EXPECT_LT(relative_l2, 0.02);
  EXPECT_GT(sliding, 300);
  EXPECT_LE(worst_ratio, 0.4 * 1.05);
  std::printf(
      "daemon stroke: %d moves (offline %zu), largest step %.4f N, relative L2 against the "
      "offline stroke %.3f %%, lateral/normal once sliding at most %.4f (%d periods)\n",
      served.moves, offline.moves.size(), served.largest_step_n, 100 * relative_l2, worst_ratio,
      sliding);
}

TEST(SlidingTool, WithoutFrictionTheDaemonSendsNoLateralForce) {
  const Served served = Serve(Stroke(0.0, 0.0));
  double lateral = 0, normal = 0;
  for (const auto& f : served.force_n) {
    lateral = std::max(lateral, std::hypot(f[0], f[1]));
    normal = std::max(normal, -f[2]);
  }
  EXPECT_GE(served.moves, 3);
  EXPECT_GT(normal, 0.5);
  EXPECT_LT(lateral, 0.05);
  EXPECT_LE(served.largest_step_n, 0.1);
  std::printf("frictionless: lateral at most %.4f N, normal up to %.3f N, %d moves\n", lateral,
              normal, served.moves);
}

// The palpation phantom at 5 mm voxels stroked by a point tip (contact.radius 0: the push on one
// cell's four nodes), 60 mm along x at 3 mm, the regions following, and jolted mid-stroke (the
// hand 1 mm deeper for 3 periods). With the spring taken at each substep's start, the light
// nodes under the stiff spring rang at the substep rate and a jolt like this one (or a move of the
// regions on threads) set them bouncing on and off the tool for the rest of the stroke: measured
// 191 to 1,494 periods with a step over 0.15 N, up to 2 N, the port guard's slew off. Taken at the
// step's end (ProxyPush), the jolt is felt, then it is over.
TEST(SlidingTool, APointTipOnFineVoxelsJoltedMidStrokeSettlesInsteadOfChattering) {
  Scene scene = LoadSceneFile(std::string(HAPTICSIM_EXAMPLES_DIR) + "/palpation/palpation.toml");
  scene.geometry.spacing_m = 0.005;
  LoadSceneGeometry(&scene);
  scene.contact.model = ContactModel::kProxy;
  scene.contact.radius_m = 0;
  scene.adaptivity.primary_size = 4;
  scene.input.contact_node = LatticeIndex{2, 4, 0};
  HapticLoop::Options options;
  options.port.max_force_rate_n_per_ms = 100;  // the force as simulated, not slewed
  options.port.passivity = false;
  HapticLoop loop(scene, options);
  const RegionConfiguration configuration{4, scene.adaptivity.secondary_lod,
                                          scene.adaptivity.secondary_rate_hz};
  const auto smooth = [](double t) { return t <= 0 ? 0.0 : t >= 1 ? 1.0 : t * t * (3 - 2 * t); };
  testing::SentForces sent;
  int moves = 0, steps_after_jolt = 0;
  double largest_before_jolt = 0;
  std::int64_t release = 1'000'000'000;
  for (int n = 0; n < 4000; ++n, release += 1'000'000) {
    if (loop.contact_following() && loop.wanted_contact_node() != loop.centre_node()) {
      loop.Reconfigure(SceneWith(scene, configuration, *loop.wanted_contact_node()),
                       HapticLoop::Handover::kCarryMotion);
      ++moves;
    }
    const double t = n * 1e-3;
    const double in = smooth(t / 0.4) - smooth((t - 3.4) / 0.4);
    const double jolt = n >= 1500 && n < 1503 ? 0.001 : 0.0;
    const std::array<double, 3> tip{0.01 + 0.06 * smooth((t - 0.5) / 2.8), 0.02,
                                    -0.002 + 0.005 * in + jolt};
    testing::PlayPeriodInVirtualTime(loop, release, DeviceSample{n, release, tip, false});
    sent.Pop(loop, [&](const std::array<double, 3>&, double step) {
      if (n < 1500) largest_before_jolt = std::max(largest_before_jolt, step);
      if (n >= 1510 && step > 0.15) ++steps_after_jolt;
    });
  }
  std::printf(
      "point tip on 5 mm voxels: %d moves, largest step before the jolt %.3f N, %d steps "
      "over 0.15 N from 7 ms after it\n",
      moves, largest_before_jolt, steps_after_jolt);
  EXPECT_GE(moves, 8);
  EXPECT_LT(largest_before_jolt, 0.1);
  EXPECT_EQ(steps_after_jolt, 0);
}

// The push after a move's pause (SlidingContact::CatchUp), played on the contact itself: the tool
// slid on 0.3 mm over a 5 ms pause. The first push is the one held, to rounding; then the push
// comes back to the tool's over twice the pause without a step and inside the friction cone, and
// once caught up it is the push of the same path played without the pause.
TEST(SlidingTool, AfterAPauseThePushComesBackFromTheHeldOneInsideTheFrictionCone) {
  Scene scene = Stroke(0.5, 0.4);
  scene.contact.model = ContactModel::kProxy;
  constexpr int kPause = 5, kAfter = 40;
  // Down 4 mm into the middle of the front face over 0.2 s, 1 mm along x over 0.1 s (the tissue
  // dragged along, the proxy still stuck), 0.3 mm in 5 ms (paused or not), then on at 10 mm/s:
  // the push of each period from the fifth before the pause, one held through it.
  const auto slide = [&](bool paused) {
    AsyncRegions regions(scene);
    SlidingContact contact(ContactObject::Of(scene), scene.contact, 0.1);
    contact.Bind(contact.Prepare(regions));
    const LatticeIndex centre = regions.partition().contact_node();
    std::array<double, 3> tip = {0.125, 0.125, -0.001}, push{};
    std::vector<std::array<double, 3>> pushes;
    std::int64_t now = 1'000'000'000;
    for (int n = 0; n < 300 + kPause + kAfter; ++n, now += 1'000'000) {
      tip[2] = -0.001 + 0.005 * std::min(1.0, n / 200.0);
      if (n >= 200) tip[0] += n >= 300 && n < 300 + kPause ? 6e-5 : 1e-5;
      const bool step = !paused || n < 300 || n >= 300 + kPause;
      if (paused && n == 300 + kPause) contact.CatchUp(now, kPause * 1'000'000, false);
      contact.Update(tip, now, step ? std::optional<LatticeIndex>(centre) : std::nullopt);
      if (step) {
        regions.AdvanceSecondariesTo(regions.state_ticks(kPrimaryRegion) +
                                     regions.period_ticks(kPrimaryRegion));
        push = contact.StepPeriod(regions, now);
      }
      if (n >= 295) pushes.push_back(push);
    }
    return pushes;
  };
  const auto plain = slide(false), paused = slide(true);
  const auto lateral = [](const std::array<double, 3>& f) { return std::hypot(f[0], f[1]); };
  const auto step = [](const std::array<double, 3>& a, const std::array<double, 3>& b) {
    return std::hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
  };
  const std::array<double, 3> held = paused[4 + kPause];
  ASSERT_GT(held[2], 0.1);  // pushing into the face (+z)
  double largest_step = 0;
  for (std::size_t n = 5 + kPause; n < paused.size(); ++n) {
    EXPECT_LE(lateral(paused[n]), 0.5 * paused[n][2] * (1 + 1e-9)) << "period " << n;
    largest_step = std::max(largest_step, step(paused[n], paused[n - 1]));
  }
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(paused[5 + kPause][c], held[c], 1e-9) << c;
  EXPECT_LT(largest_step, 0.025);
  // Caught up (10 ms) and on for 30 ms: the push without the pause.
  EXPECT_LT(step(paused.back(), plain.back()), 0.05 * plain.back()[2]);
  std::printf(
      "after a 5 ms pause: held (%.4f, %.4f, %.4f) N, first push (the same), largest step "
      "%.4f N; 40 ms on (%.4f, %.4f, %.4f) N, without the pause (%.4f, %.4f, %.4f) N\n",
      held[0], held[1], held[2], largest_step, paused.back()[0], paused.back()[1],
      paused.back()[2], plain.back()[0], plain.back()[1], plain.back()[2]);
}

// A move's pause as the tool lifts out (the end of a stroke): the regions stand still while the
// tool rises further than the spring was compressed, so against the tissue where the pause left
// it the tool is off the surface. The push must still come back from the held one, the tissue
// following the tool up from where it was, not drop to nothing and spring back up into the tool
// (through hapticsimd on the palpation phantom beside load: 0.12 N → 0 → 0.06 N in a period) —
// also when a second pause comes before the first's catch-up is over (a switch of configuration
// right after a follow): what was still owed is owed on.
TEST(SlidingTool, AfterAPauseWhileLiftingOutThePushComesBackFromTheHeldOneNotFromZero) {
  Scene scene = Stroke(0.5, 0.4);
  scene.contact.model = ContactModel::kProxy;
  struct Pause {
    int at, periods;
  };
  // Pressed 1.5 mm into the front face's middle over 0.2 s, held 0.1 s, then lifted at 20 mm/s
  // (the device's stroke) to 0.9 mm and held there: the push, one per period, held through
  // each pause.
  const auto lift = [&](const std::vector<Pause>& pauses) {
    AsyncRegions regions(scene);
    SlidingContact contact(ContactObject::Of(scene), scene.contact, 0.1);
    contact.Bind(contact.Prepare(regions));
    const LatticeIndex centre = regions.partition().contact_node();
    std::vector<std::array<double, 3>> pushes;
    std::array<double, 3> push{};
    std::int64_t now = 1'000'000'000;
    for (int n = 0; n < 400; ++n, now += 1'000'000) {
      const double depth =
          n < 200 ? 0.0015 * n / 200 : std::clamp(0.0015 - 2e-5 * (n - 300), 0.0009, 0.0015);
      bool step = true;
      for (const Pause& p : pauses) {
        step = step && !(n >= p.at && n < p.at + p.periods);
        if (n == p.at + p.periods) contact.CatchUp(now, p.periods * 1'000'000, false);
      }
      const double z = n == 0 ? -0.001 : depth;  // touched from outside
      contact.Update({0.125, 0.125, z}, now,
                     step ? std::optional<LatticeIndex>(centre) : std::nullopt);
      if (step) {
        regions.AdvanceSecondariesTo(regions.state_ticks(kPrimaryRegion) +
                                     regions.period_ticks(kPrimaryRegion));
        push = contact.StepPeriod(regions, now);
      }
      pushes.push_back(push);
    }
    return pushes;
  };
  const auto step = [](const std::array<double, 3>& a, const std::array<double, 3>& b) {
    return std::hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
  };
  const auto plain = lift({});
  for (const std::vector<Pause>& pauses :
       {std::vector<Pause>{{322, 9}}, std::vector<Pause>{{318, 9}, {331, 5}}}) {
    const auto paused = lift(pauses);
    const std::array<double, 3> held = paused[pauses[0].at + pauses[0].periods - 1];
    // Lifted further than the spring was compressed (k = 1000 N/m): off the paused tissue.
    ASSERT_LT(held[2] / scene.contact.stiffness_n_per_m, 2e-5 * pauses[0].periods);
    ASSERT_GT(held[2], 0.02);
    for (const Pause& p : pauses) {
      EXPECT_NEAR(paused[p.at + p.periods][2], paused[p.at + p.periods - 1][2], 1e-9)
          << "the first push after the pause at " << p.at << " is not the held one";
    }
    const int last = pauses.back().at + pauses.back().periods;
    double largest_step = 0;
    for (int n = pauses[0].at + pauses[0].periods; n < last + 30; ++n) {
      largest_step = std::max(largest_step, step(paused[n], paused[n - 1]));
    }
    EXPECT_LT(largest_step, 0.02) << pauses.size() << " pause(s)";
    // Caught up, the push is the one without the pause.
    EXPECT_LT(step(paused[last + 31], plain[last + 31]), 0.01) << pauses.size() << " pause(s)";
    std::printf(
        "%zu pause(s) lifting out: held %.4f N (%.4f N without), first push the same, largest "
        "step after %.4f N; 31 ms after the last %.4f N (%.4f N without)\n",
        pauses.size(), held[2], plain[pauses[0].at + pauses[0].periods - 1][2], largest_step,
        paused[last + 31][2], plain[last + 31][2]);
  }
}

// Regions restarted from rest under a sliding tool (a runaway's demotion, a move the check refused
// and took back: Handover::kRampIn) in the middle of the slide: the tool touches again where it is
// — not stuck waiting for a node that may have been refused — and its push ramps back in from zero
// without a step.
TEST(SlidingTool, RegionsRestartedFromRestUnderTheToolTouchAgainAndRampIn) {
  const Scene scene = Stroke(0.5, 0.4);
  const RegionConfiguration configuration{3, 2, 600};
  const Served plain = Serve(scene);
  const Served restarted = Serve(scene, [&](long n, HapticLoop& loop) {
    if (n == 600) {
      loop.Reconfigure(SceneWith(scene, configuration, loop.centre_node()),
                       HapticLoop::Handover::kRampIn);
    }
  });
  EXPECT_LE(restarted.largest_step_n, 0.1);
  // In contact again once the 0.1 s ramp is over, pushing back at least half as hard as the stroke
  // without the restart (the object restarted from rest settles under the tool anew: measured 0.89
  // against 0.48 N 0.2 s after, the tissue still coming back up under the spring).
  const double before = -plain.force_n[800][2], after = -restarted.force_n[800][2];
  EXPECT_GT(before, 0.3);
  EXPECT_GT(after, 0.5 * before);
  std::printf(
      "restarted from rest at 0.6 s: normal %.3f N at 0.8 s (%.3f N without), largest step "
      "%.4f N\n",
      after, before, restarted.largest_step_n);
}

// Regions moved under an engaged tool onto another face (a follow to a node whose normal is not
// the touched face's): nothing pushes the tool sideways; the touch waits for regions on its own
// face (asking for them) and engages again there, its push ramped in.
TEST(SlidingTool, RegionsMovedToAnotherFaceUnderTheToolPushNothingThereAndTheTouchWaits) {
  const Scene scene = Stroke(0.5, 0.4);
  const RegionConfiguration configuration{3, 2, 600};
  bool asked_back = false;
  double largest_after = 0;
  const Served served = Serve(scene, [&](long n, HapticLoop& loop) {
    if (n == 500) {
      loop.Reconfigure(SceneWith(scene, configuration, LatticeIndex{0, 6, 6}),
                       HapticLoop::Handover::kCarryMotion);
    }
    if (n > 500 && n < 520 && loop.contact_waiting()) {
      const std::optional<LatticeIndex> wanted = loop.wanted_contact_node();
      asked_back = asked_back || (wanted && (*wanted)[2] == 0);
    }
    if (n == 520 && loop.wanted_contact_node()) {  // the supervisor moves them there
      loop.Reconfigure(SceneWith(scene, configuration, *loop.wanted_contact_node()),
                       HapticLoop::Handover::kRampIn);
    }
  });
  for (long n = 501; n < 520; ++n) {
    const auto& f = served.force_n[static_cast<std::size_t>(n)];
    largest_after = std::max(largest_after, std::hypot(f[0], f[1]));
  }
  EXPECT_TRUE(asked_back) << "the waiting touch did not ask for regions on its face";
  EXPECT_LT(largest_after, 0.5 * -served.force_n[499][2] + 1e-9)
      << "a sideways push beyond the friction the tool had";
  EXPECT_GT(-served.force_n[800][2], 0.3) << "the tool did not touch again on its face";
}

// The stroke on past the front face's rim (x = 0.25 m), still 5 mm in: the tool leaves the cube
// sideways while pushing (0.13 N, the rim's edge giving way). Let go in one period, the push
// stepped the hand by all of it; it fades out over SlidingContact::kRelease_ns instead, flagged in
// contact, and then nothing is felt while the tool is outside.
TEST(SlidingTool, AToolThatLeavesTheObjectSidewaysWhilePushingLetsGoSmoothly) {
  Scene scene = Stroke(0.5, 0.4);
  scene.input.stroke_length_m = 0.14;
  const ContactTrajectory path(scene.input);
  long out = -1;  // the first period with the tip past the rim
  for (long n = 0; out < 0 && n < 10'000; ++n) {
    if (0.125 + path.DisplacementAt(static_cast<double>(n) * 1e-3)[0] > 0.25) out = n;
  }
  ASSERT_GT(out, 0);
  const Served served = Serve(scene);
  ASSERT_GT(served.force_n.size(), static_cast<std::size_t>(out + 40));
  const auto magnitude = [&](long n) {
    const auto& f = served.force_n[static_cast<std::size_t>(n)];
    return std::hypot(f[0], f[1], f[2]);
  };
  const double pushing = magnitude(out - 1);
  EXPECT_GT(pushing, 0.1) << "the tool was not pushing as it left";
  double largest_step = 0;
  for (long n = out - 5; n < out + 40; ++n) {
    const auto& a = served.force_n[static_cast<std::size_t>(n - 1)];
    const auto& b = served.force_n[static_cast<std::size_t>(n)];
    largest_step = std::max(largest_step, std::hypot(b[0] - a[0], b[1] - a[1], b[2] - a[2]));
  }
  const long released_ms = SlidingContact::kRelease_ns / 1'000'000;
  EXPECT_GT(magnitude(out + released_ms / 2), 0.3 * pushing) << "let go at once";
  for (long n = out; n < out + released_ms - 1; ++n) {
    EXPECT_TRUE(served.flags[static_cast<std::size_t>(n)] & force_flags::kInContact)
        << "a fading push not flagged in contact, period " << n;
  }
  for (long n = out + released_ms + 2; n < out + 40; ++n) {
    EXPECT_EQ(magnitude(n), 0.0) << "a force outside the object, period " << n;
  }
  // A smoothstep over 20 periods changes the push by at most 1.5 / 20 = 7.5 % of it a period; at
  // once it would be all of it.
  EXPECT_LT(largest_step, 0.15 * pushing);
  std::printf("off the rim: push %.3f N as the tool left, largest step after %.3f N\n",
              magnitude(out - 1), largest_step);
}

// A tool lifted straight out lets go at once, with no fade: the tissue is pressed in behind the
// face's plane, so the spring has let go before the tip leaves the object, and only a tip still
// more than 0.5 mm past the plane releases by a fade (SlidingContact::PressedIn). Back in 3 ms
// later it touches again at once. A lift-off that faded would have left a tip back inside within
// the fade waiting, pushing nothing, for a lift-off it had already made.
TEST(SlidingTool, AToolLiftedStraightOutAndBackInAtOnceTouchesAgain) {
  Scene scene = Stroke(0.5, 0.4);
  const auto tip_at = [](long n) -> std::array<double, 3> {
    double z = 0;
    if (n < 100)
      z = -0.001 + 4e-5 * n;  // in to 3 mm at 40 mm/s
    else if (n < 200)
      z = 0.003;  // held
    else if (n < 235)
      z = 0.003 - 1e-4 * (n - 200);  // out at 0.1 m/s, to −0.5 mm
    else if (n < 238)
      z = -0.0005;  // 3 ms out
    else
      z = std::min(0.002, -0.0005 + 1e-4 * (n - 238));  // back in, to 2 mm
    return {0.125, 0.125, z};
  };
  const Served served = Serve(
      scene, [](long, HapticLoop&) {}, tip_at);
  ASSERT_GT(served.force_n.size(), 400u);
  for (long n = 232; n < 238; ++n) {  // the tip out from 230 on: nothing rendered out there
    const auto& f = served.force_n[static_cast<std::size_t>(n)];
    if (tip_at(n)[2] < 0) {
      EXPECT_LT(std::hypot(f[0], f[1], f[2]), 0.02) << "period " << n;
    }
  }
  EXPECT_GT(-served.force_n[400][2], 0.2) << "the tool back in did not touch again";
  EXPECT_TRUE(served.flags[400] & force_flags::kInContact);
}

}  // namespace
}  // namespace hapticsim
