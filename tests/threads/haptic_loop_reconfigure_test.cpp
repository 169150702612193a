// hapticsimd's loop on real threads and real clocks while its regions are replaced: every period
// is answered, and a touch on another node is answered after the regions move there, with its
// force ramped in rather than stepped.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <optional>
#include <thread>
#include <vector>

#include "daemon/haptic_loop.hpp"
#include "daemon/supervisor.hpp"
#include "tests/support/late_wakes.hpp"
#include "tests/support/play_device.hpp"
#include "tests/support/sanitized.hpp"

namespace hapticsim {
namespace {

constexpr double kH = 0.25 / 12;  // the default 13³ cube's node spacing

// Under a sanitizer every step is several times slower than its period: the hand-over protocol
// is checked (that is what the sanitizer is for), the forces are not (see RealTimeSchedule's
// CompletesWithFiniteForcesWhateverTheTiming for what a lagging region does to them).

Scene AdaptiveScene() {
  Scene scene;
  scene.adaptivity.primary_size = 3;
  return scene;
}

// One run of the loop answering a hovering tool while its regions are replaced six times.
struct ReplacementRun {
  std::vector<ForceRecord> forces;
  std::int64_t paused_periods = 0;
  std::size_t dropped = 0;
  // An answer is stamped when its period ends, at most (worst lateness + longest step) after its
  // release: how far the stamps may lag the release grid, periods.
  double stamp_delay_periods = 0;
};

ReplacementRun AnswerWhileReplacing(const Scene& scene) {
  HapticLoop loop(scene, HapticLoop::Options{});
  loop.Start();
  std::atomic<int> replaced{0};
  // The supervisor's part: replace the regions six times, 100 ms apart, alternating the
  // configuration and the node.
  std::thread supervisor([&] {
    for (int k = 0; k < 6; ++k) {
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
      const bool odd = k % 2 == 1;
      loop.Reconfigure(SceneWith(scene, RegionConfiguration{odd ? 3 : 2, 2, 600},
                                 odd ? LatticeIndex{6, 6, 0} : LatticeIndex{3, 9, 0}));
      // Where the replacement's time went (the supervisor logs a slow one): its parts add up.
      const HapticLoop::ReplacementTimes& took = loop.last_replacement();
      EXPECT_GT(took.build_s, 0);
      EXPECT_GT(took.pause_s, 0);
      EXPECT_GE(took.join_s, 0);
      EXPECT_GE(took.total_s, took.build_s + took.pause_s + took.join_s);
      EXPECT_LT(took.total_s, took.build_s + took.pause_s + took.join_s + 0.5);
      std::printf("replacement %d: %.1f ms (building %.1f, pausing %.1f, joining %.1f)\n", k,
                  1e3 * took.total_s, 1e3 * took.build_s, 1e3 * took.pause_s, 1e3 * took.join_s);
      ++replaced;
    }
  });
  ReplacementRun run;
  run.forces = testing::PlayDevice(
      loop, 300,
      [](int) {
        return std::array<double, 3>{0.1, 0.1, -0.002};
      },
      [&] { return replaced == 6; });
  supervisor.join();
  loop.Stop();
  run.paused_periods = loop.paused_periods();
  run.dropped = loop.forces().dropped();
  const DeadlineSnapshot primary = loop.monitor(kPrimaryRegion).TakeSnapshot();
  run.stamp_delay_periods =
      (primary.worst_lateness_s + primary.recent_execution_max_s) / primary.period_s;
  return run;
}

TEST(HapticLoopReconfigure, EveryPrimaryPeriodIsAnsweredWhileTheRegionsAreReplaced) {
  // A primary that lagged 25 periods or more (a stall of the machine's: CI's have lasted 30 to
  // 100 ms) leaves the count below too loose to tell a lost answer: run again, up to three times.
  // Under a sanitizer every step is slower and the stamps lag 25 to 50 periods beside two busy
  // threads: there the hand-over is what is checked, and a lost answer only where it shows.
  ReplacementRun run;
  for (int attempt = 1; attempt <= 3; ++attempt) {
    run = AnswerWhileReplacing(AdaptiveScene());
    if (kSanitized || run.stamp_delay_periods < 25) break;
    std::printf("attempt %d: the stamps lagged up to %.1f periods; again\n", attempt,
                run.stamp_delay_periods);
  }
  EXPECT_GT(run.paused_periods, 0);
  // One answer per release: the primary's release grid from the first answer to the last. The
  // span between the first and last stamps is the releases between them give or take the stamps'
  // lag. A stop and restart would lose at least 5 periods per reconfiguration, 30 here.
  const std::vector<ForceRecord>& forces = run.forces;
  ASSERT_GT(forces.size(), 100u);
  const double span_periods = (forces.back().utime_us - forces.front().utime_us) / 1000.0;
  EXPECT_NEAR(static_cast<double>(forces.size()) - 1, span_periods,
              std::max(2.0, 0.005 * span_periods) + run.stamp_delay_periods)
      << "answers lost or doubled across six reconfigurations (the stamps lag their releases by "
      << "up to " << run.stamp_delay_periods << " periods)";
  if (!kSanitized) {
    EXPECT_LT(run.stamp_delay_periods, 25) << "the primary lagged too far for the count to tell";
  }
  EXPECT_EQ(run.dropped, 0u) << "the answer ring overflowed";
  for (size_t i = 1; i < forces.size(); ++i) ASSERT_GE(forces[i].seq, forces[i - 1].seq);
}

// The input at which PressAt's tool stops, 6 mm in: the force changes most there, by however the
// object happens to be moving (its own transient since it started from rest).
constexpr int kPressStopInput = 700;

struct PressResult {
  std::vector<ForceRecord> forces;
  double largest_jump_n = 0;           // largest force change between periods woken on time
  std::int64_t largest_jump_seq = 0;   // the input it answered
  double largest_jump_pressing_n = 0;  // … while the tool moves in, before its stop
  std::int64_t largest_jump_pressing_seq = 0;
  double largest_jump_any_n = 0;  // and between any two periods
  int near_late_wakes = 0;        // answers from a period woken late or just after one
  double final_force_n = 0;
  double held_mean_force_n = 0;  // over the hold's last 100 answers: the ring-down averaged out
  bool moved = false;
};

// Fewer than `fraction` of the press's answers came from periods woken late or just after one.
bool MostlyOnTime(const PressResult& press, double fraction) {
  return press.near_late_wakes < fraction * static_cast<double>(press.forces.size());
}

// The force changes between periods (z) of a press: over the periods woken on time, and over all.
void MeasureJumps(PressResult* result) {
  std::vector<Wake> wakes;
  for (const ForceRecord& f : result->forces) {
    wakes.push_back({f.period, f.utime_us, (f.flags & force_flags::kInputStale) != 0});
  }
  const std::vector<bool> near_late = NearALateWake(wakes);
  double previous = 0;
  for (size_t i = 0; i < result->forces.size(); ++i) {
    const double force = result->forces[i].force_n[2];
    const double jump = std::abs(force - previous);
    if (near_late[i]) {
      ++result->near_late_wakes;
    } else {
      if (jump > result->largest_jump_n) {
        result->largest_jump_n = jump;
        result->largest_jump_seq = result->forces[i].seq;
      }
      if (result->forces[i].seq < kPressStopInput && jump > result->largest_jump_pressing_n) {
        result->largest_jump_pressing_n = jump;
        result->largest_jump_pressing_seq = result->forces[i].seq;
      }
    }
    result->largest_jump_any_n = std::max(result->largest_jump_any_n, jump);
    previous = force;
  }
  result->final_force_n = previous;
  const size_t tail = std::min<size_t>(100, result->forces.size());
  for (size_t i = result->forces.size() - tail; i < result->forces.size(); ++i) {
    result->held_mean_force_n += result->forces[i].force_n[2] / static_cast<double>(tail);
  }
}

// Above `node` for 100 ms, then in at 10 mm/s for 0.6 s, then held for 0.8 s, on a loop centred
// on `centre`; a stand-in supervisor moves the regions onto the touched node 200 ms after the
// touch asks for it (longer than the daemon's stability check around a new node takes).
PressResult PressAt(const LatticeIndex& node, const LatticeIndex& centre) {
  const Scene scene = SceneWith(AdaptiveScene(), RegionConfiguration{3, 2, 600}, centre);
  HapticLoop loop(scene, HapticLoop::Options{});
  loop.Start();
  std::atomic<bool> done{false}, moved{false};
  std::thread supervisor([&] {
    while (!done && !loop.contact_waiting()) {
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    if (done) return;
    EXPECT_EQ(loop.wanted_contact_node(), node);
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    loop.Reconfigure(SceneWith(scene, RegionConfiguration{3, 2, 600}, node),
                     HapticLoop::Handover::kRampIn);
    moved = true;
  });
  PressResult result;
  result.forces = testing::PlayDevice(loop, 1500, [&](int n) {
    const double z = n < 100 ? -0.001 : 1e-5 * std::min(n - 100, kPressStopInput - 100);
    return std::array<double, 3>{node[0] * kH, node[1] * kH, z};
  });
  done = true;
  supervisor.join();
  loop.Stop();
  EXPECT_EQ(loop.centre_node(), node);
  MeasureJumps(&result);
  result.moved = moved;
  return result;
}

TEST(HapticLoopReconfigure, ATouchOnAnotherNodeIsAnsweredAfterRecentringWithoutAForceStep) {
  const LatticeIndex side{2, 3, 0};
  // Pressed again, up to three times, where the machine woke two in five of either press's
  // answers late (see below): the smoothness is measured over the others.
  PressResult centred, moved;
  for (int attempt = 1; attempt <= 3; ++attempt) {
    centred = PressAt(side, side);  // the same press, no re-centring needed
    moved = PressAt(side, LatticeIndex{6, 6, 0});
    if (kSanitized || (MostlyOnTime(centred, 0.4) && MostlyOnTime(moved, 0.4))) break;
    std::printf("attempt %d: %d and %d of %zu answers near a late wake; pressing again\n", attempt,
                centred.near_late_wakes, moved.near_late_wakes, moved.forces.size());
  }
  EXPECT_FALSE(centred.moved);
  ASSERT_TRUE(moved.moved) << "the touch never asked for the regions";
  int waiting = 0, engaged = 0;
  for (const ForceRecord& f : moved.forces) {
    ASSERT_TRUE(std::isfinite(f.force_n[2]));
    if (!(f.flags & force_flags::kInContact)) {
      EXPECT_EQ(f.force_n[2], 0.0) << "force out of contact at seq " << f.seq;
      if (f.seq > 100 && (f.flags & force_flags::kReconfiguring)) ++waiting;
    } else {
      ++engaged;
    }
  }
  EXPECT_GT(waiting, 150) << "the touch should wait (zero force, flagged) for its regions";
  EXPECT_GT(engaged, 0);
  if (kSanitized) return;
  EXPECT_GT(engaged, 500);
  // Pressed 6 mm at a node a quarter of the way in from the edge: the object pushes back (−z),
  // once the ramp is over as hard as when the regions were there from the start. Compared over
  // the hold's last 100 ms: the stop at 10 mm/s leaves the object ringing, and the two runs'
  // different histories put it in different phases. After a 0.4 s hold (d = 10/s: 13 % of the
  // ringing left) single answers differed by 3.4 % once in a suite run, and the means by 3.3 %
  // in 1 run of 6 on a quiet machine; after 0.8 s, 2 % of it is left.
  EXPECT_LT(moved.final_force_n, -0.3);
  EXPECT_NEAR(moved.held_mean_force_n, centred.held_mean_force_n,
              0.02 * std::abs(centred.held_mean_force_n));
  std::printf(
      "held force, last 100 ms: %.4f N re-centred, %.4f N centred; last answers %.4f and "
      "%.4f N\n",
      moved.held_mean_force_n, centred.held_mean_force_n, moved.final_force_n,
      centred.final_force_n);
  // The 2 mm pressed while waiting ramps in: no force change between periods larger than the
  // ordinary press's own (its touch-down and its stop), and far below the step it would be.
  const double step_if_not_ramped = std::abs(moved.final_force_n) * 0.002 / 0.006;
  std::printf(
      "largest force change between periods: %.4f N re-centred (input %lld), %.4f N centred "
      "from the start (input %lld); unramped the waiting depth would step by %.3f N (answers "
      "near a late wake, left out: %d and %d of %zu)\n",
      moved.largest_jump_n, static_cast<long long>(moved.largest_jump_seq), centred.largest_jump_n,
      static_cast<long long>(centred.largest_jump_seq), step_if_not_ramped, moved.near_late_wakes,
      centred.near_late_wakes, moved.forces.size());
  std::printf(
      "while pressing in, before the stop: %.4f N re-centred (input %lld), %.4f N centred "
      "(input %lld)\n",
      moved.largest_jump_pressing_n, static_cast<long long>(moved.largest_jump_pressing_seq),
      centred.largest_jump_pressing_n, static_cast<long long>(centred.largest_jump_pressing_seq));
  // Left out: under one per cent on a quiet machine, 1 to 14 % with two busy loops beside it;
  // on a noisier VM (2026-12-05) 2 to 21 % idle, once 37 %. Two in five, and what is left says
  // nothing about smoothness.
  EXPECT_TRUE(MostlyOnTime(moved, 0.4) && MostlyOnTime(centred, 0.4))
      << "two in five answers or more near a late wake in each of three pairs of presses: "
      << moved.near_late_wakes << " and " << centred.near_late_wakes << " of "
      << moved.forces.size();
  // The wait, the move and the ramp-in are all before the stop: there, no change larger than the
  // ordinary press's own. (At the stop itself the force changes by however the object happens to
  // be moving then, which differs between regions started from rest at different times: 0.036
  // to 0.044 N re-centred, 0.021 to 0.03 N centred, in runs on this machine; the ramp-in's
  // largest was 0.0075 N.) Over the whole press, stop included, far below the unramped step.
  // Not 1.25 ×: once in 12 quiet runs a period woken on time stepped by 0.0386 N at input 435,
  // long after the ramp-in, against the centred touch-down's 0.0295 N (1.31 ×). The filter sees
  // only the primary's wakes; a secondary woken late, its boundary older, is the likely cause.
  EXPECT_LT(moved.largest_jump_pressing_n, 1.5 * centred.largest_jump_n);
  EXPECT_LT(moved.largest_jump_n, 0.5 * step_if_not_ramped);
}

// The paper's press (1 cm, 1 Hz: z = 5 mm · (1 − cos 2πt)) on the front face's middle after
// 100 ms above it, on real threads. With `switch_configurations`, a stand-in supervisor switches
// the configuration three times while the tool is in (as hapticsimd does once a better one is
// verified), carrying the motion. `busy_threads` spin beside the loop meanwhile, as a desktop
// load does (no real-time privileges).
PressResult PaperPress(bool switch_configurations, int busy_threads) {
  const Scene scene = SceneWith(AdaptiveScene(), RegionConfiguration{3, 2, 1000}, {6, 6, 0});
  HapticLoop loop(scene, HapticLoop::Options{});
  loop.Start();
  std::atomic<bool> done{false};
  std::vector<std::thread> busy;
  for (int b = 0; b < busy_threads; ++b) {
    busy.emplace_back([&] {
      volatile double x = 1;
      while (!done) x = x * 1.0000001 + 1e-9;
    });
  }
  std::atomic<int> switched{0};
  std::thread supervisor([&] {
    if (!switch_configurations) return;
    const RegionConfiguration switches[] = {{2, 3, 600}, {4, 2, 800}, {3, 2, 1000}};
    for (const RegionConfiguration& to : switches) {
      std::this_thread::sleep_for(std::chrono::milliseconds(240));
      if (done) return;
      loop.Reconfigure(SceneWith(scene, to, {6, 6, 0}), HapticLoop::Handover::kCarryMotion);
      ++switched;
    }
  });
  PressResult result;
  // Played on (out of contact after the press) until the switches are done: under a sanitizer
  // building new regions takes longer than the press.
  result.forces = testing::PlayDevice(
      loop, 1100,
      [](int n) {
        const double t = (n - 100) * 1e-3;
        const double z = n < 100 ? -0.001 : 0.005 * (1 - std::cos(2 * M_PI * std::min(t, 1.0)));
        return std::array<double, 3>{6 * kH, 6 * kH, std::max(z, -0.001)};
      },
      [&] { return !switch_configurations || switched == 3; });
  done = true;
  supervisor.join();
  for (std::thread& b : busy) b.join();
  loop.Stop();
  result.moved = switched == 3;
  MeasureJumps(&result);
  return result;
}

// Each switch in a press: the answers from the one before its hold (the periods answered while
// the new regions were installed, flagged reconfiguring in contact) to the fifth after it.
struct SwitchWindow {
  double largest_jump_n = 0;          // between any two consecutive answers in it
  double largest_on_time_jump_n = 0;  // … of those where neither is near a late wake
  int on_time_steps = 0;              // how many steps are between two such answers
};

std::vector<SwitchWindow> SwitchWindows(const std::vector<ForceRecord>& forces) {
  std::vector<Wake> wakes;
  for (const ForceRecord& f : forces) {
    wakes.push_back({f.period, f.utime_us, (f.flags & force_flags::kInputStale) != 0});
  }
  const std::vector<bool> near_late = NearALateWake(wakes);
  auto held = [&](size_t i) {
    return (forces[i].flags & force_flags::kReconfiguring) &&
           (forces[i].flags & force_flags::kInContact);
  };
  std::vector<SwitchWindow> windows;
  for (size_t i = 1; i < forces.size(); ++i) {
    if (!held(i) || held(i - 1)) continue;
    size_t end = i;
    while (end < forces.size() && held(end)) ++end;
    SwitchWindow w;
    for (size_t k = i; k < std::min(forces.size(), end + 5); ++k) {
      const double jump = std::abs(forces[k].force_n[2] - forces[k - 1].force_n[2]);
      const bool on_time = !near_late[k] && !near_late[k - 1];
      w.largest_jump_n = std::max(w.largest_jump_n, jump);
      if (on_time) w.largest_on_time_jump_n = std::max(w.largest_on_time_jump_n, jump);
      w.on_time_steps += on_time;
    }
    windows.push_back(w);
    i = end;
  }
  return windows;
}

// A configuration switched while the tool presses: the force is held for the few periods the new
// regions are being installed (never dropped to zero), the object's motion carries over, and the
// force does not step by more than 0.1 N between periods — quiet, and beside two busy threads.
TEST(HapticLoopReconfigure, AConfigurationSwitchedInThePressCarriesTheForceWithoutAStep) {
  for (int busy : {0, 2}) {
    // Pressed again, up to three times, where the machine woke half the switched press's answers
    // late (see below): the smoothness is measured over the others.
    PressResult plain, switched;
    for (int attempt = 1; attempt <= 3; ++attempt) {
      plain = PaperPress(false, busy);
      switched = PaperPress(true, busy);
      if (kSanitized || MostlyOnTime(switched, 0.5)) break;
      std::printf("%d busy threads, attempt %d: %d of %zu answers near a late wake; again\n", busy,
                  attempt, switched.near_late_wakes, switched.forces.size());
    }
    ASSERT_TRUE(switched.moved) << "the stand-in supervisor did not switch three times";
    int held = 0;
    for (const ForceRecord& f : switched.forces) {
      ASSERT_TRUE(std::isfinite(f.force_n[2]));
      if ((f.flags & force_flags::kReconfiguring) && (f.flags & force_flags::kInContact)) {
        ++held;
        // (Under a sanitizer an install outlasts the 50 ms hold and the force is released: the
        // hand-over is checked there, the forces are not, as above.)
        if (!kSanitized) {
          EXPECT_LT(f.force_n[2], -0.05) << "the force was dropped while the regions were replaced";
        }
      }
    }
    EXPECT_GT(held, 3) << "no period was answered while the regions were replaced";
    const std::vector<SwitchWindow> windows = SwitchWindows(switched.forces);
    int on_time_steps = 0;
    double across_on_time = 0, across_any = 0;
    for (const SwitchWindow& w : windows) {
      across_any = std::max(across_any, w.largest_jump_n);
      across_on_time = std::max(across_on_time, w.largest_on_time_jump_n);
      on_time_steps += w.on_time_steps;
    }
    std::printf(
        "%d busy threads: %zu holds, %d steps in them between periods woken on time; largest "
        "change across a switch %.4f N between periods woken on time, %.4f N any\n",
        busy, windows.size(), on_time_steps, across_on_time, across_any);
    std::printf(
        "%d busy threads: largest force change between periods woken on time %.4f N with 3 "
        "switches in the press (%d periods held), %.4f N without; between any periods %.4f N "
        "and %.4f N (answers near a late wake: %d and %d of %zu)\n",
        busy, switched.largest_jump_n, held, plain.largest_jump_n, switched.largest_jump_any_n,
        plain.largest_jump_any_n, switched.near_late_wakes, plain.near_late_wakes,
        switched.forces.size());
    if (kSanitized) continue;
    // (Under a sanitizer a switch may come after the press, out of contact: no hold.)
    EXPECT_EQ(windows.size(), 3u) << "each switch in the press is a hold of its own";
    // Beside two busy threads 1–31 % of the answers were near a late wake (with or without
    // switches): half, and what is left still covers the press.
    EXPECT_TRUE(MostlyOnTime(switched, 0.5))
        << "half the answers or more near a late wake in each of three presses: "
        << switched.near_late_wakes << " of " << switched.forces.size();
    // Both presses are smooth between periods woken on time: under the 0.1 N of every smoothness
    // check (measured in 40 runs: up to 0.047 N switched and 0.041 N plain quiet, 0.042 N and
    // 0.051 N beside two busy threads). And at the switches (each hold and the five periods after
    // it), no step between periods woken on time exceeds the plain press's largest by more than
    // 50 mN (measured: up to 0.043 N). Measured at the switches, not as the switched press's
    // largest change over all: that was once an input stall's 0.067 N, the device thread held
    // up 9 ms and the tip predicted meanwhile, far from any switch; what input stalls do is the
    // input prediction's to test (InputPrediction, docs/reliability.md).
    EXPECT_LE(plain.largest_jump_n, 0.1);
    EXPECT_LE(switched.largest_jump_n, 0.1);
    EXPECT_GT(on_time_steps, 0) << "no step at any switch was woken on time: nothing measured";
    EXPECT_LE(across_on_time, plain.largest_jump_n + 0.05);
    // Across each switch itself, late wakes included: a late wake there is no excuse for a step.
    // Quiet, the 0.1 N of every smoothness check; beside busy threads, where a late wake alone
    // steps the force (the soak's worst in contact under load: 0.2 N), 0.25 N.
    EXPECT_LE(across_any, busy == 0 ? 0.1 : 0.25);
  }
}

// A tool that slides (contact.model = "proxy") on real threads: a stand-in supervisor moves the
// regions onto the node the proxy wants whenever the loop asks to be followed, carrying the
// object's motion (SlidingContact::Bind runs on its thread while the primary has paused them:
// under ThreadSanitizer this checks that hand-over). The force is held over each move and blends
// back: no step over 0.1 N between periods woken on time, and the push is never dropped while the
// regions are replaced.
TEST(HapticLoopReconfigure, ASlidingToolsRegionsFollowItWithTheForceHeldAndBlendedBack) {
  Scene scene = AdaptiveScene();
  scene.contact.model = ContactModel::kProxy;
  HapticLoop loop(scene, HapticLoop::Options{});
  loop.Start();
  std::atomic<bool> done{false};
  std::atomic<int> moves{0};
  std::thread supervisor([&] {
    while (!done) {
      const std::optional<LatticeIndex> wanted = loop.wanted_contact_node();
      if (loop.contact_following() && wanted && *wanted != loop.centre_node()) {
        loop.Reconfigure(SceneWith(scene, RegionConfiguration{3, 2, 600}, *wanted),
                         HapticLoop::Handover::kCarryMotion);
        ++moves;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
  });
  // 0.2 s above the middle of the front face, 0.3 s in to 5 mm, then 60 mm along x in 1.2 s.
  const auto forces = testing::PlayDevice(loop, 1800, [](int n) {
    const double in = std::clamp((n - 200) / 300.0, 0.0, 1.0);
    const double along = std::clamp((n - 500) / 1200.0, 0.0, 1.0);
    return std::array<double, 3>{0.125 + 0.06 * along, 0.125, n < 200 ? -0.002 : 0.005 * in};
  });
  done = true;
  supervisor.join();
  loop.Stop();
  EXPECT_GE(moves, 2) << "the regions did not follow the proxy across the face";
  int held = 0, late = 0;
  double largest = 0, largest_late = 0;
  const ForceRecord* last = nullptr;
  bool last_late = false;
  for (const ForceRecord& f : forces) {
    // A period that woke late took more than one input, or came more than 1.5 periods after the
    // last: the tool moved two periods' worth in it (and back to one in the next).
    const bool woke_late = last && (f.seq > f.first_seq || f.utime_us - last->utime_us > 1500);
    ASSERT_TRUE(std::isfinite(f.force_n[0] + f.force_n[1] + f.force_n[2]));
    const bool in_contact = f.flags & force_flags::kInContact;
    if (in_contact && (f.flags & force_flags::kReconfiguring)) {
      ++held;
      if (!kSanitized) {
        EXPECT_LT(f.force_n[2], -0.05) << "the push was dropped during a move";
      }
    }
    if (last && in_contact && (last->flags & force_flags::kInContact)) {
      const double step =
          std::hypot(f.force_n[0] - last->force_n[0], f.force_n[1] - last->force_n[1],
                     f.force_n[2] - last->force_n[2]);
      if (woke_late || last_late) {
        ++late;
        largest_late = std::max(largest_late, step);
      } else {
        largest = std::max(largest, step);
      }
    }
    last = &f;
    last_late = woke_late;
  }
  std::printf(
      "sliding on threads: %d moves, %d periods held, largest step %.4f N (%.4f N in %d steps "
      "about a late wake)\n",
      moves.load(), held, largest, largest_late, late);
  if (kSanitized) return;
  EXPECT_GT(held, 0) << "no period was answered while the regions moved";
  // Periods on time, across the moves' holds and blends: the smoothness checks' 0.1 N. Late wakes
  // step a sliding force too (the tool moved two periods' worth): the soak's 0.2 N, its bound
  // beside load. (Once in a full suite, 0.164 N, where the test did not yet tell them apart.)
  EXPECT_LE(largest, 0.1);
  EXPECT_LE(largest_late, 0.2);
}

}  // namespace
}  // namespace hapticsim
