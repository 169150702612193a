// hapticsimd end to end on a real LCM bus: run only inside a private network namespace
// (tests/support/in_private_netns.sh creates one: loopback up, a multicast route on it), so the
// daemon's default udpm:// URL is used as in production and no packet leaves the namespace.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/mman.h>
#include <sys/ptrace.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <lcm/lcm-cpp.hpp>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <thread>

#include "core/errormap/error_map.hpp"
#include "core/errormap/error_map_file.hpp"
#include "core/errormap/map_axes.hpp"
#include "core/scene/scene.hpp"
#include "hapticsim/command_t.hpp"
#include "hapticsim/device_input_t.hpp"
#include "hapticsim/force_feedback_t.hpp"
#include "hapticsim/status_t.hpp"
#include "ipc/control_client.hpp"
#include "ipc/shm_device_client.hpp"
#include "tests/support/daemon_harness.hpp"
#include "tests/support/fake_systemd.hpp"
#include "tests/support/late_wakes.hpp"
#include "tests/support/poll_until.hpp"
#include "tests/support/private_socket.hpp"
#include "tests/support/run_command.hpp"

namespace hapticsim {
namespace {

using Clock = std::chrono::steady_clock;
using testing::Client;
using testing::FakeSystemd;
using testing::ThreadOf;
using testing::WaitUntilServing;
constexpr double kEdge = 0.25;  // the default cube

std::string Temp(const std::string& name) {
  return ::testing::TempDir() + "hapticsimd_e2e_" + name;
}

// A map made by the real sweep over the grid file text `axes`; returns its path.
std::string SweptMap(const std::string& name, const std::string& axes) {
  const std::string grid = Temp(name + "_grid.toml"), map = Temp(name + ".hsmap");
  std::ofstream(grid) << "[axes]\n" << axes;
  const auto result =
      testing::RunCommand({HAPTICSIM_CLI_PATH, "sweep", "--grid", grid, "--out", map, "--json"});
  EXPECT_EQ(result.exit_status, 0) << result.err;
  return map;
}

// A two-configuration map for the default scene, made by the real sweep (a few seconds): the
// primary sizes 1 (cheaper, about 2.7 % error) and 3 (about 0.4 %).
const std::string& SmallMap() {
  static const std::string path =
      SweptMap("map",
               "secondary_lod = [2]\nprimary_size = [1, 3]\nsecondary_rate = [1000.0]\n"
               "frequency = [1.0]\n");
  return path;
}

class HapticsimdEndToEnd : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string config = Temp("hapticsimd.toml");
    control_ = testing::PrivateSocketPath();
    std::ofstream(config) << "# the defaults, and a map\n[supervisor]\nerror_map = \"" << SmallMap()
                          << "\"\nerror_target_percent = 7.0\n[lcm]\n"
                             "url = \"udpm://239.255.76.67:7667?ttl=0\"\n"
                          << "[control]\nsocket = \"" << control_ << "\"\n";
    daemon_ = std::make_unique<testing::BackgroundProcess>(
        std::vector<std::string>{HAPTICSIMD_PATH, "--config", config}, Temp("daemon.log"));
  }
  void TearDown() override {
    daemon_.reset();  // stopped (SIGKILL if still running) before its socket's directory goes
    std::filesystem::remove_all(std::filesystem::path(control_).parent_path());
  }
  // A request over the control socket, as `hapticsim ctl` sends it; the daemon's answer.
  std::string Ctl(const std::string& line) { return shm::SendControlRequest(control_, line, 5000); }
  std::string control_;
  std::unique_ptr<testing::BackgroundProcess> daemon_;
};

// Press into the object at the contact point at 1 kHz: 0.3 s above the surface, then 1 cm in.
TEST_F(HapticsimdEndToEnd, AnswersDeviceInputWithForceErrorAndItsSeq) {
  Client client;
  ASSERT_TRUE(client.WaitForStatus([](const status_t&) { return true; }, 30))
      << "no status from the daemon; its log:\n"
      << daemon_->Log();
  // Nothing touches it yet: the regions sleep (and a touch wakes them, below).
  EXPECT_TRUE(client.WaitForStatus([](const status_t& s) { return s.asleep && s.sleeps >= 1; }, 5));
  std::set<std::int64_t> sent;
  auto next = Clock::now();
  for (std::int64_t seq = 1; seq <= 1300; ++seq) {
    const double z = seq <= 300 ? -0.005 : 0.01 * std::min(1.0, (seq - 300) / 500.0);
    client.Send(seq, kEdge / 2, kEdge / 2, z);
    sent.insert(seq);
    next += std::chrono::milliseconds(1);
    std::this_thread::sleep_until(next);
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  const std::vector<force_feedback_t> forces = client.Forces();
  ASSERT_GT(forces.size(), 1000u) << daemon_->Log();
  int in_contact = 0, pushing_back = 0;
  for (const force_feedback_t& f : forces) {
    EXPECT_TRUE(sent.count(f.seq)) << "a force answers seq " << f.seq << ", never sent";
    EXPECT_TRUE(std::isfinite(f.force[0] + f.force[1] + f.force[2]));
    EXPECT_GT(f.error_percent, 0.0);  // the looked-up error of the active configuration
    EXPECT_FALSE(f.flags & force_feedback_t::FLAG_NO_ERROR_MAP);
    if (f.seq <= 300) {
      EXPECT_FALSE(f.flags & force_feedback_t::FLAG_IN_CONTACT) << f.seq;
      EXPECT_EQ(f.force[2], 0.0) << "force out of contact at seq " << f.seq;
    }
    if (f.flags & force_feedback_t::FLAG_IN_CONTACT) ++in_contact;
    if (f.seq > 1100 && f.force[2] < -0.5) ++pushing_back;  // 1 cm press: about 1.3 N back
  }
  EXPECT_GT(in_contact, 700);
  EXPECT_GT(pushing_back, 100);
  // Seqs come back in order.
  for (size_t i = 1; i < forces.size(); ++i) EXPECT_GE(forces[i].seq, forces[i - 1].seq);

  const std::optional<status_t> status = client.LastStatus();
  ASSERT_TRUE(status);
  EXPECT_EQ(status->num_regions, 2);
  EXPECT_EQ(status->regions[0].name, "primary");
  EXPECT_DOUBLE_EQ(status->regions[0].rate_hz, 1000.0);
  EXPECT_GT(status->regions[0].cycles, 1000);
  EXPECT_GT(status->regions[0].execution_p50_us, 0.0);
  EXPECT_DOUBLE_EQ(status->error_target_percent, 7.0);
  EXPECT_TRUE(status->target_met);
  EXPECT_GE(status->inputs_received, 1300);
  EXPECT_EQ(status->spectral_radius, -1.0) << "not estimated: the runaway watch guards";
  EXPECT_EQ(status->runaways, 0) << "the default scene's regions hold their energy balance";
  EXPECT_FALSE(status->asleep) << "pressing in at the end";

  daemon_->Signal(SIGTERM);
  EXPECT_EQ(daemon_->Wait(5), 0) << daemon_->Log();
  EXPECT_NE(daemon_->Log().find("stopped cleanly"), std::string::npos) << daemon_->Log();
}

TEST_F(HapticsimdEndToEnd, BadInputIsRejectedCountedAndTheDaemonKeepsServing) {
  Client client;
  ASSERT_TRUE(client.WaitForStatus([](const status_t&) { return true; }, 30)) << daemon_->Log();
  for (std::int64_t seq = 1; seq <= 50; ++seq) {
    client.Send(seq, kEdge / 2, kEdge / 2, 0.002);
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  client.Send(51, NAN, kEdge / 2, 0.002);              // non-finite
  client.Send(52, kEdge / 2, kEdge / 2, 5.0);          // far outside the workspace
  client.Send(53, kEdge / 2 + 0.2, kEdge / 2, 0.002);  // a jump no hand can make in 1 ms
  client.Send(40, kEdge / 2, kEdge / 2, 0.002);        // an old seq
  client.SendRaw("this is not an LCM message");
  ASSERT_TRUE(client.WaitForStatus(
      [](const status_t& s) { return s.inputs_rejected >= 4 && s.decode_errors >= 1; }, 5))
      << daemon_->Log();
  for (std::int64_t seq = 54; seq <= 300; ++seq) {
    client.Send(seq, kEdge / 2, kEdge / 2, 0.002);
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  const auto forces = client.Forces();
  ASSERT_FALSE(forces.empty());
  EXPECT_EQ(forces.back().seq, 300) << "the daemon stopped answering after bad input";
  for (const auto& f : forces) EXPECT_TRUE(std::isfinite(f.force[2]));
  EXPECT_NE(daemon_->Log().find("device input rejected"), std::string::npos);
}

TEST_F(HapticsimdEndToEnd, ACommandChangesTheErrorTargetAndTheSupervisorReconfigures) {
  Client client;
  // The cheapest configuration that meets 7 %: primary size 1.
  ASSERT_TRUE(client.WaitForStatus(
      [](const status_t& s) { return s.target_met && s.primary_size == 1; }, 30))
      << daemon_->Log();
  EXPECT_EQ(Ctl("set-error-target 0.001"), "ok: error target 0.001 %; choosing again");
  // Unreachable: the supervisor keeps the most accurate stable configuration (size 3), switched
  // while nothing touches the object, and flags the target as exceeded.
  ASSERT_TRUE(client.WaitForStatus(
      [](const status_t& s) {
        return s.error_target_percent == 0.001 && !s.target_met && s.primary_size == 3;
      },
      15))
      << daemon_->Log();
  for (std::int64_t seq = 1; seq <= 100; ++seq) {  // from above the surface into the object
    client.Send(seq, kEdge / 2, kEdge / 2, seq <= 20 ? -0.002 : 0.001);
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  const auto forces = client.Forces();
  ASSERT_FALSE(forces.empty());
  EXPECT_TRUE(forces.back().flags & force_feedback_t::FLAG_ERROR_TARGET_EXCEEDED);
  // Invalid: refused with the reason, the target unchanged.
  EXPECT_EQ(Ctl("set-error-target -3"),
            "refused: SET_ERROR_TARGET -3 refused: the target must be in (0, 100] %");
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  EXPECT_EQ(client.LastStatus()->error_target_percent, 0.001);
  // In contact, a new target switches the configuration as soon as it is verified: the object's
  // motion carries over, so the force goes on, neither dropped nor stepped.
  for (std::int64_t seq = 101; seq <= 900; ++seq) {  // in to 8 mm at 10 mm/s, then held
    client.Send(seq, kEdge / 2, kEdge / 2, std::min(0.008, 0.001 + 1e-5 * (seq - 100)));
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  const size_t before = client.Forces().size();
  ASSERT_GT(before, 0u);
  const std::int64_t replaced_before = client.LastStatus()->reconfigurations;
  EXPECT_EQ(Ctl("set-error-target 5").rfind("ok:", 0), 0u);  // size 1 meets it, and is cheaper
  for (std::int64_t seq = 901; seq <= 2400; ++seq) {         // held at 8 mm for 1.5 s
    client.Send(seq, kEdge / 2, kEdge / 2, 0.008);
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  const std::optional<status_t> switched = client.LastStatus();
  EXPECT_EQ(switched->primary_size, 1) << "not switched in contact\n" << daemon_->Log();
  EXPECT_GT(switched->reconfigurations, replaced_before) << "the regions were never replaced";
  const auto pressed = client.Forces();
  const double pressing_n = pressed[before - 1].force[2];
  ASSERT_LT(pressing_n, -0.5) << "8 mm in pushes back with about 0.7 N";
  // The force nearest to zero and farthest from it, N (z < 0 pushes back).
  double largest_step = 0, weakest = -1e9, strongest = 0;
  int held_answers = 0, switching_answers = 0;
  for (size_t i = before; i < pressed.size(); ++i) {
    // After the last input the answers go stale and the force is released: not the switch's.
    if (pressed[i].flags & force_feedback_t::FLAG_INPUT_STALE) break;
    ASSERT_TRUE(pressed[i].flags & force_feedback_t::FLAG_IN_CONTACT) << "seq " << pressed[i].seq;
    ++held_answers;
    if (pressed[i].flags & force_feedback_t::FLAG_RECONFIGURING) ++switching_answers;
    largest_step = std::max(largest_step, std::abs(pressed[i].force[2] - pressed[i - 1].force[2]));
    weakest = std::max(weakest, static_cast<double>(pressed[i].force[2]));
    strongest = std::min(strongest, static_cast<double>(pressed[i].force[2]));
  }
  std::printf(
      "switched in contact at 8 mm: largest force change between periods %.4f N, force "
      "between %.3f N and %.3f N (it pressed with %.3f N before); %d answers held, %d of them "
      "while the regions were replaced\n",
      largest_step, strongest, weakest, pressing_n, held_answers, switching_answers);
  // The switch happened among the answers measured, so the step and the force below are
  // measured across it. (The window ends at the first stale answer: after the last input, or
  // where a stall of the test over 50 ms stopped the input. The switch comes within tens of ms
  // of the command; measured: 1,702 and 1,720 answers held, 6 while replaced.)
  EXPECT_GT(held_answers, 100) << daemon_->Log();
  EXPECT_GT(switching_answers, 0) << "no answer in contact came while the regions were replaced";
  EXPECT_LE(largest_step, 0.1);
  // It relaxes from the press's overshoot towards the static 0.7–0.75 N; a force dropped and
  // ramped in again (a switch from rest) would pass near zero.
  EXPECT_LT(weakest, -0.5) << "the force was dropped across the switch\n" << daemon_->Log();
}

// What one touch off centre measured (HapticsimdEndToEnd.ATouchOffCentre...).
struct RecentringRun {
  double touch_to_force_ms = 0;
  int waited = 0;           // periods flagged waiting for the regions to move
  int pushing_back = 0;     // answers in the held press pushing back over 0.3 N
  int near_late = 0;        // answers from a period woken late or just after one
  int on_time = 0;          // the others: the steps measured
  int on_time_in_ramp = 0;  // … of them in the engage ramp (0.1 s from the first force)
  double largest_jump = 0;  // N, between answers of periods woken on time
  size_t answers = 0;

  // The steps measured cover the re-centring: its ramp-in, and the press after it. (Not most of
  // the answers: CI's machine once woke 811–1,157 of 1,600 late in three touches running alone.)
  bool MeasuredEnough() const { return on_time_in_ramp >= 10 && on_time >= 200; }
};

// Hovers over surface node (2, 3, 0), presses 6 mm in over 600 ms and holds; checks what the
// daemon says it did and measures the force it answered with.
void TouchOffCentre(Client& client, testing::BackgroundProcess& daemon, RecentringRun* run) {
  ASSERT_TRUE(client.WaitForStatus([](const status_t& s) { return s.contact_node[2] == 0; }, 30))
      << daemon.Log();
  const double h = kEdge / 12;
  auto next = Clock::now();
  for (std::int64_t seq = 1; seq <= 1500; ++seq) {  // a brief hover over (2, 3, 0), then 6 mm in
    const double z = seq <= 50 ? -0.002 : 0.006 * std::min(1.0, (seq - 50) / 600.0);
    client.Send(seq, 2 * h, 3 * h, z);
    next += std::chrono::milliseconds(1);
    std::this_thread::sleep_until(next);
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  const std::optional<status_t> status = client.LastStatus();
  ASSERT_TRUE(status);
  EXPECT_EQ(status->contact_node[0], 2);
  EXPECT_EQ(status->contact_node[1], 3);
  EXPECT_EQ(status->contact_node[2], 0);
  EXPECT_GE(status->reconfigurations, 1);
  EXPECT_EQ(status->runaways, 0);
  EXPECT_NE(daemon.Log().find("regions centred on contact node (2, 3, 0)"), std::string::npos)
      << daemon.Log();
  EXPECT_NE(daemon.Log().find("around contact node (2, 3, 0) checked"), std::string::npos)
      << "the check behind the move\n"
      << daemon.Log();
  std::int64_t touch_down_us = -1, first_force_us = -1;  // seq 51 is the first input inside
  double previous = 0;
  const std::vector<force_feedback_t> forces = client.Forces();
  std::vector<Wake> wakes;
  for (const force_feedback_t& f : forces) {
    wakes.push_back({f.period, f.utime, (f.flags & force_feedback_t::FLAG_INPUT_STALE) != 0});
  }
  const std::vector<bool> near_late_wake = NearALateWake(wakes);
  for (size_t i = 0; i < forces.size(); ++i) {
    const force_feedback_t& f = forces[i];
    ASSERT_TRUE(std::isfinite(f.force[2]));
    if (f.seq > 50 && touch_down_us < 0) touch_down_us = f.utime;
    if (f.seq > 50 && f.force[2] != 0 && first_force_us < 0) first_force_us = f.utime;
    if (!(f.flags & force_feedback_t::FLAG_IN_CONTACT)) {
      EXPECT_EQ(f.force[2], 0.0) << "force without contact at seq " << f.seq;
      if (f.seq > 50 && (f.flags & force_feedback_t::FLAG_RECONFIGURING)) ++run->waited;
    } else {
      // Off the node the map was made for: the error is the mapped node's, flagged as clamped.
      EXPECT_TRUE(f.flags & force_feedback_t::FLAG_LOOKUP_CLAMPED) << f.seq;
      if (f.seq > 1300 && f.force[2] < -0.3) ++run->pushing_back;
    }
    if (f.flags & force_feedback_t::FLAG_INPUT_STALE) continue;  // zeroed once the device stops
    if (near_late_wake[i]) {
      ++run->near_late;  // the machine's hiccup, not the re-centring's
                         // (tests/support/late_wakes.hpp)
    } else {
      run->largest_jump = std::max(run->largest_jump, std::abs(f.force[2] - previous));
      ++run->on_time;
      if (first_force_us >= 0 && f.utime <= first_force_us + 100'000) ++run->on_time_in_ramp;
    }
    previous = f.force[2];
  }
  ASSERT_GE(touch_down_us, 0);
  ASSERT_GE(first_force_us, 0) << "no force after the touch";
  run->touch_to_force_ms = (first_force_us - touch_down_us) * 1e-3;
  run->answers = forces.size();
  std::printf(
      "re-centring: %.1f ms from touch-down to the first force (%d periods flagged waiting); "
      "largest force step %.4f N over periods woken on time (%d of them in the ramp-in); %d of "
      "%zu answers near a late wake\n",
      run->touch_to_force_ms, run->waited, run->largest_jump, run->on_time_in_ramp, run->near_late,
      run->answers);
}

// Contact anywhere: a touch on another surface node moves the regions there at once (their
// coupling verified behind them) and pushes back with its force ramped in, within 20 ms.
TEST_F(HapticsimdEndToEnd, ATouchOffCentreMovesTheRegionsThereAndPushesBack) {
  // The force's smoothness is measured over the periods woken on time (a late wake's step through
  // the held boundary is the stall tests'), so it needs enough of them where the re-centring is:
  // where the machine woke nearly all of the ramp-in late, the touch is made again, on a fresh
  // daemon, up to three times. Late answers measured: 0–12 of 1,600 on a quiet machine, 61–339
  // beside two to eight busy processes, 657–1,157 in CI (where the steps on time were 0.015–0.031
  // N); the largest step over all answers was the on-time one's here, or under 0.09 N.
  RecentringRun run;
  for (int attempt = 1; attempt <= 3; ++attempt) {
    if (attempt > 1) {
      TearDown();
      SetUp();
    }
    run = RecentringRun{};
    Client client;
    TouchOffCentre(client, *daemon_, &run);
    if (HasFatalFailure()) return;
    daemon_->Signal(SIGTERM);
    EXPECT_EQ(daemon_->Wait(5), 0) << daemon_->Log();
    // A stall of the machine's across the touch (CI's have lasted 30 to 100 ms) delays the first
    // force by itself: touched again too (measured 9–14 ms quiet, 10–13 ms beside busy threads).
    if (run.MeasuredEnough() && run.touch_to_force_ms <= 20.0) break;
    std::printf(
        "attempt %d: %d of %zu answers woken on time, %d in the ramp-in, the first force %.1f ms "
        "after the touch; touching again\n",
        attempt, run.on_time, run.answers, run.on_time_in_ramp, run.touch_to_force_ms);
  }
  EXPECT_LE(run.touch_to_force_ms, 20.0) << "from touch-down to the first force\n"
                                         << daemon_->Log();
  EXPECT_GT(run.pushing_back, 100) << daemon_->Log();
  EXPECT_LT(run.largest_jump, 0.1) << "a force step across the re-centring";
  EXPECT_TRUE(run.MeasuredEnough())
      << "too few answers woken on time to measure the re-centring, in each of three touches: "
      << run.on_time << " of " << run.answers << ", " << run.on_time_in_ramp << " in the ramp-in";
}

TEST_F(HapticsimdEndToEnd, APinnedConfigurationHoldsUntilReleasedAndAnOutOfRangeOneIsRefused) {
  Client client;
  ASSERT_TRUE(client.WaitForStatus([](const status_t& s) { return s.primary_size == 1; }, 30))
      << daemon_->Log();
  EXPECT_EQ(Ctl("pin 3 2 1000").rfind("ok: verifying", 0), 0u);
  ASSERT_TRUE(
      client.WaitForStatus([](const status_t& s) { return s.pinned && s.primary_size == 3; }, 15))
      << daemon_->Log();
  // Faster than the primary, or no primary region: refused before anything is built.
  EXPECT_EQ(Ctl("pin 3 2 5000").rfind("refused: PIN_CONFIGURATION refused", 0), 0u);
  EXPECT_EQ(Ctl("pin 0 2 1000").rfind("refused: PIN_CONFIGURATION refused", 0), 0u);
  EXPECT_EQ(Ctl("pin 3 2"),
            "refused: pin takes three numbers: primary_size, secondary_lod, "
            "secondary rate in Hz");
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  EXPECT_EQ(client.LastStatus()->primary_size, 3);
  EXPECT_EQ(Ctl("release"), "ok: released; choosing freely again");
  ASSERT_TRUE(
      client.WaitForStatus([](const status_t& s) { return !s.pinned && s.primary_size == 1; }, 15))
      << daemon_->Log();
}

// Stability first: a simulated force above device.fault_force_n latches a fault: the force sent
// (never above device.max_force_n) ramps to zero and stays there, the black box of the last
// periods is logged and the simulation restarts from rest.
TEST(HapticsimdFaults, AForceAboveTheLimitIsNeverSentAndTheBlackBoxIsLogged) {
  const std::string config = Temp("fault.toml");
  // A 1 cm press gives about 1.3 N.
  std::ofstream(config) << "[device]\nmax_force_n = 0.4\nfault_force_n = 0.5\n";
  testing::BackgroundProcess daemon({HAPTICSIMD_PATH, "--config", config}, Temp("fault.log"));
  Client client;
  ASSERT_TRUE(client.WaitForStatus([](const status_t&) { return true; }, 30)) << daemon.Log();
  for (std::int64_t seq = 1; seq <= 800; ++seq) {  // from above the surface, 1 cm in
    client.Send(seq, kEdge / 2, kEdge / 2,
                seq <= 50 ? -0.002 : 0.01 * std::min(1.0, (seq - 50) / 400.0));
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  const auto forces = client.Forces();
  ASSERT_GT(forces.size(), 500u);
  for (const auto& f : forces) {
    EXPECT_LE(std::hypot(f.force[0], f.force[1], f.force[2]), 0.4 + 1e-12) << "seq " << f.seq;
  }
  EXPECT_TRUE(std::any_of(forces.begin(), forces.end(), [](const force_feedback_t& f) {
    return f.flags & force_feedback_t::FLAG_FAULT_LATCHED;
  }));
  const std::string log = daemon.Log();
  EXPECT_NE(log.find("force fault"), std::string::npos) << log;
  // After the fault nothing is rendered until the tool leaves the object: one fault, not a storm.
  size_t faults = 0;
  for (size_t at = 0; (at = log.find("force fault latched (", at)) != std::string::npos; ++at) {
    ++faults;
  }
  EXPECT_EQ(faults, 1u) << log;
  EXPECT_FALSE(forces.back().flags & force_feedback_t::FLAG_IN_CONTACT);
  EXPECT_NE(log.find("black box (force fault): the last"), std::string::npos) << log;
  EXPECT_NE(log.find("black box: t +0.0 ms seq"), std::string::npos) << log;

  // The tool leaves the object: the simulation, restarted from rest, re-arms the fault.
  std::int64_t seq = 800;
  auto play = [&](int periods, const std::function<double(int)>& z) {
    for (int n = 0; n < periods; ++n) {
      client.Send(++seq, kEdge / 2, kEdge / 2, z(n));
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  };
  play(300, [](int) { return -0.002; });
  ASSERT_TRUE(client.WaitForStatus(
      [](const status_t& s) { return s.fault_rearms == 1 && !s.fault_latched; }, 5))
      << "not re-armed with the tool out\n"
      << daemon.Log();
  EXPECT_GE(client.LastStatus()->reconfigurations, 1) << "the regions were not restarted";
  // A press within the limits afterwards is rendered: 2 mm in at 10 mm/s, held (about 0.27 N).
  const size_t before = client.Forces().size();
  play(700, [](int n) { return std::min(0.002, -0.002 + 2e-5 * n); });
  const auto again = client.Forces();
  ASSERT_GT(again.size(), before + 500);
  const force_feedback_t& held = again.back();
  EXPECT_TRUE(held.flags & force_feedback_t::FLAG_IN_CONTACT) << held.flags;
  EXPECT_FALSE(held.flags & force_feedback_t::FLAG_FAULT_LATCHED) << held.flags;
  EXPECT_LT(held.force[2], -0.15) << "the press after the re-arm was not rendered";
  EXPECT_GT(held.force[2], -0.4);
  EXPECT_EQ(client.LastStatus()->latched_faults, 1) << daemon.Log();
  std::printf("after the re-arm, held 2 mm in: %.3f N\n", held.force[2]);
  daemon.Signal(SIGTERM);
  EXPECT_EQ(daemon.Wait(5), 0);
}

// A map over two contact nodes where the cheapest configuration meets the target at the middle of
// the front face but not two nodes from its edge: there the supervisor chooses again, for that
// node, and switches once that choice is verified. Errors of this grid (the real sweep, spacing
// factor 3, 1000 Hz): primary size 1 about 1.8 % at (6, 6, 0) and 6.9 % at (2, 6, 0); size 4 below
// 1 % at both, and several times dearer (its box is 13 × 13 × 7 nodes at the middle).
TEST(HapticsimdContactNodes, WhereTheConfigurationMissesTheTargetTheSupervisorChoosesForThatNode) {
  const std::string map =
      SweptMap("nodes",
               "secondary_lod = [3]\nprimary_size = [1, 4]\nsecondary_rate = [1000.0]\n"
               "frequency = [1.0]\ncontact_node_x = [2, 6]\n");
  auto error_of = [&](int size, const char* node) {
    const auto looked_up = testing::RunCommand(
        {HAPTICSIM_CLI_PATH, "lookup", map, "--set", "primary_size=" + std::to_string(size),
         "--set", "secondary_lod=3", "--set", "secondary_rate=1000", "--set",
         std::string("contact_node=") + node, "--json"});
    EXPECT_EQ(looked_up.exit_status, 0) << looked_up.err;
    return nlohmann::json::parse(looked_up.out).at("error").get<double>();
  };
  constexpr double kTarget = 3.0;
  // What the test stands on: size 1 meets the target at the middle and misses it at (2, 6, 0).
  ASSERT_LT(error_of(1, "6,6,0"), kTarget);
  ASSERT_GT(error_of(1, "2,6,0"), kTarget);
  const std::string config = Temp("nodes.toml");
  std::ofstream(config) << "[supervisor]\nerror_map = \"" << map
                        << "\"\nerror_target_percent = " << kTarget << "\n";
  testing::BackgroundProcess daemon({HAPTICSIMD_PATH, "--config", config}, Temp("nodes.log"));
  Client client;
  ASSERT_TRUE(client.WaitForStatus(
      [](const status_t& s) { return s.primary_size == 1 && s.target_met; }, 30))
      << daemon.Log();

  const double h = kEdge / 12;
  auto next = Clock::now();
  std::int64_t seq = 0;
  auto play = [&](int periods, double z) {
    for (int i = 0; i < periods; ++i) {
      client.Send(++seq, 2 * h, 6 * h, z);
      next += std::chrono::milliseconds(1);
      std::this_thread::sleep_until(next);
    }
  };
  play(50, -0.002);   // hover over (2, 6, 0)
  play(1200, 0.004);  // 4 mm in: the regions move there, size 1 still running
  const size_t in_contact = client.Forces().size();
  play(3000, -0.002);  // lift off and hover: the new choice has switched by now
  ASSERT_TRUE(client.WaitForStatus(
      [](const status_t& s) {
        return s.contact_node[0] == 2 && s.contact_node[1] == 6 && s.contact_node[2] == 0 &&
               s.primary_size != 1 && s.target_met && s.error_percent <= kTarget;
      },
      10))
      << daemon.Log();
  EXPECT_NE(daemon.Log().find("around contact node (2, 6, 0) the looked-up error of primary_size "
                              "1, secondary_lod 3, secondary_rate 1000 Hz is"),
            std::string::npos)
      << daemon.Log();
  // While size 1 ran around (2, 6, 0) its forces said the target was exceeded; once the better
  // configuration took over in contact (no stability estimate to wait for), they no longer do.
  const std::vector<force_feedback_t> forces = client.Forces();
  int flagged = 0, flagged_late = 0, late = 0;
  for (size_t i = 0; i < in_contact && i < forces.size(); ++i) {
    if (!(forces[i].flags & force_feedback_t::FLAG_IN_CONTACT)) continue;
    const bool exceeded = forces[i].flags & force_feedback_t::FLAG_ERROR_TARGET_EXCEEDED;
    flagged += exceeded;
    if (i + 500 >= in_contact) ++late, flagged_late += exceeded;
  }
  EXPECT_GT(flagged, 0) << daemon.Log();
  EXPECT_GT(late, 400);
  EXPECT_EQ(flagged_late, 0) << "the last 0.5 s in contact ran the configuration chosen for it\n"
                             << daemon.Log();
  daemon.Signal(SIGTERM);
  EXPECT_EQ(daemon.Wait(5), 0) << daemon.Log();
}

// Stable by construction, end to end (docs/regions.md, "The runaway watch"): a stiff small scene
// (stress seed 1, case 160: E 1.17 MPa, 7³ nodes, a primary one element deep, the secondary at
// 700 Hz) whose state, touched at its own node, outgrows what its energy balance allows with the
// interface controllers on (`hapticsim simulate` on it: the watch ends it at 32–57 ms). No
// estimate refuses it any more: the daemon runs it, the runaway watch fires, the regions go to
// the secondaries at the primary rate around that node and the status counts it. The force sent
// stays finite and within the envelope throughout, and at equal rates a second press is answered
// as `simulate` answers it at equal rates, with no runaway more.
TEST(HapticsimdRunaway, AStateThatOutgrowsItsBalanceTakesTheRegionsToEqualRates) {
  const std::string scene = Temp("runaway_scene.toml");
  const auto written =
      testing::RunCommand({HAPTICSIM_CLI_PATH, "stress", "--seed", "1", "--max-nodes", "7",
                           "--case", "160", "--scene-out", scene});
  ASSERT_EQ(written.exit_status, 0) << written.err;
  // What the press should feel like at equal rates: `simulate` on the same scene, a slow press
  // to the same depth (quasi-static at 0.5 Hz), on the virtual-time schedule.
  constexpr double kDepth = 0.0003;
  const auto offline = testing::RunCommand(
      {HAPTICSIM_CLI_PATH, "simulate", "--json", "--scene", scene, "--set",
       "adaptivity.secondary_rate=1000", "--set", "adaptivity.outer_rate=1000", "--set",
       "input.waveform=press", "--set", "input.amplitude=" + std::to_string(kDepth), "--set",
       "input.frequency=0.5", "--set", "input.contact_node=3,6,5"});
  ASSERT_EQ(offline.exit_status, 0) << offline.err;
  const double expected_n = nlohmann::json::parse(offline.out)["peak_force_N"].get<double>();
  const std::string config = Temp("runaway.toml");
  std::ofstream(config) << "[scene]\nfile = \"" << scene << "\"\n";
  testing::BackgroundProcess daemon({HAPTICSIMD_PATH, "--config", config}, Temp("runaway.log"));
  Client client;
  ASSERT_TRUE(client.WaitForStatus(
      [](const status_t& s) { return s.secondary_rate_hz == 700 && s.num_regions == 2; }, 30))
      << daemon.Log();
  // Node (3, 6, 5) of the 7³ cube (spacing h): on the face y = edge, pressed along −y.
  const double h = kEdge / 6;
  auto next = Clock::now();
  std::int64_t seq = 0;
  constexpr int kPressInputs = 1400;
  auto press = [&](double depth_m) {  // hover 50 ms, in over 200 ms, hold 750 ms, out, hover
    for (int i = 0; i < kPressInputs; ++i) {
      const double in = i < 50 ? 0 : i < 250 ? (i - 50) / 200.0 : i < 1000 ? 1 : 0;
      client.Send(++seq, 3 * h, kEdge + 0.002 - (0.002 + depth_m) * in, 5 * h);
      next += std::chrono::milliseconds(1);
      std::this_thread::sleep_until(next);
    }
  };
  press(kDepth);
  ASSERT_TRUE(client.WaitForStatus(
      [](const status_t& s) { return s.runaways >= 1 && s.secondary_rate_hz == 1000; }, 5))
      << daemon.Log();
  const std::string log = daemon.Log();
  EXPECT_NE(log.find("outgrew what the energy balance allows (runaway watch: "), std::string::npos)
      << log;
  EXPECT_NE(log.find(" J allowed); secondaries at the primary rate there"), std::string::npos)
      << log;
  const std::int64_t runaways = client.LastStatus()->runaways;
  const size_t first_press = client.Forces().size();
  press(kDepth);
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  const std::optional<status_t> status = client.LastStatus();
  ASSERT_TRUE(status);
  EXPECT_EQ(status->runaways, runaways) << "none at equal rates\n" << daemon.Log();
  EXPECT_EQ(status->secondary_rate_hz, 1000);
  const std::vector<force_feedback_t> forces = client.Forces();
  ASSERT_GT(forces.size(), first_press + 1000);
  // The second press's hold: its inputs 600–999 (seq from kPressInputs + 1), 350 ms after the
  // tool stopped. Not the press-in, whose tissue damping adds to the force by how fast the tool
  // went in, and which the engage ramp hides or not by where the first period in contact fell.
  const std::int64_t hold_from = kPressInputs + 600, hold_to = kPressInputs + 1000;
  std::vector<double> held_n;
  for (size_t i = 0; i < forces.size(); ++i) {
    const double f = std::hypot(forces[i].force[0], forces[i].force[1], forces[i].force[2]);
    ASSERT_TRUE(std::isfinite(f)) << "seq " << forces[i].seq;
    EXPECT_LE(f, status->max_force_n + 1e-12) << "seq " << forces[i].seq;
    if (i > first_press && (forces[i].flags & force_feedback_t::FLAG_IN_CONTACT) &&
        forces[i].seq > hold_from && forces[i].seq <= hold_to) {
      held_n.push_back(f);
    }
  }
  ASSERT_GT(held_n.size(), 300u) << "the hold answered in contact\n" << daemon.Log();
  std::nth_element(held_n.begin(), held_n.begin() + held_n.size() / 2, held_n.end());
  const double held = held_n[held_n.size() / 2];  // the median over the hold
  ASSERT_LT(expected_n, status->max_force_n) << "a press the envelope does not clip";
  EXPECT_NEAR(held, expected_n, 0.03 * expected_n) << "the second press, at equal rates\n"
                                                   << daemon.Log();
  std::printf(
      "runaway: %lld watch firing(s); the second press at equal rates held %.3f N (median) "
      "(offline %.3f N)\n",
      static_cast<long long>(status->runaways), held, expected_n);
  daemon.Signal(SIGTERM);
  EXPECT_EQ(daemon.Wait(5), 0) << daemon.Log();
}

// SIGHUP reloads the map; a damaged one is refused and the loaded one kept, and the loop runs on.
TEST(HapticsimdReload, ACorruptMapOnReloadIsRefusedAndTheDaemonKeepsServing) {
  const std::string map = Temp("reload.hsmap");
  std::filesystem::copy_file(SmallMap(), map, std::filesystem::copy_options::overwrite_existing);
  const std::string config = Temp("reload.toml");
  std::ofstream(config) << "[supervisor]\nerror_map = \"" << map << "\"\n";
  testing::BackgroundProcess daemon({HAPTICSIMD_PATH, "--config", config}, Temp("reload.log"));
  Client client;
  ASSERT_TRUE(client.WaitForStatus([](const status_t& s) { return s.error_percent > 0; }, 30))
      << daemon.Log();
  const double error = client.LastStatus()->error_percent;
  std::filesystem::resize_file(map, std::filesystem::file_size(map) / 2);  // truncated
  daemon.Signal(SIGHUP);
  const auto deadline = Clock::now() + std::chrono::seconds(5);
  while (daemon.Log().find("truncated") == std::string::npos && Clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  EXPECT_NE(daemon.Log().find("refused: truncated"), std::string::npos) << daemon.Log();
  EXPECT_NE(daemon.Log().find("keeping the map loaded before"), std::string::npos);
  // The loop serves on: input sent now is answered (with no device it sleeps, so its period
  // count says nothing).
  const size_t answered = client.Forces().size();
  auto next = Clock::now();
  for (std::int64_t seq = 1; seq <= 300; ++seq) {
    client.Send(seq, kEdge / 2, kEdge / 2, -0.005);
    next += std::chrono::milliseconds(1);
    std::this_thread::sleep_until(next);
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  ASSERT_TRUE(daemon.running()) << daemon.Log();
  EXPECT_GT(client.Forces().size(), answered + 250) << "the loop stopped";
  EXPECT_EQ(client.LastStatus()->error_percent, error) << "the loaded map was dropped";

  // A config with a mistake is refused whole; a good one changes the target at once.
  const status_t before_reload = *client.LastStatus();
  std::ofstream(config) << "[supervisor]\nerror_map = \"" << map << "\"\nerror_target = 3\n";
  daemon.Signal(SIGHUP);
  EXPECT_TRUE(testing::PollUntil(
      [&] { return daemon.Log().find("config reload refused") != std::string::npos; },
      std::chrono::seconds(5)))
      << daemon.Log();
  EXPECT_EQ(client.LastStatus()->error_target_percent, before_reload.error_target_percent);
  EXPECT_EQ(client.LastStatus()->error_map, before_reload.error_map);
  EXPECT_EQ(client.LastStatus()->error_percent, error) << "the refused config changed the map";
  std::ofstream(config) << "[supervisor]\nerror_map = \"" << map
                        << "\"\nerror_target_percent = 3.5\n";
  daemon.Signal(SIGHUP);
  EXPECT_TRUE(
      client.WaitForStatus([](const status_t& s) { return s.error_target_percent == 3.5; }, 5))
      << daemon.Log();
  daemon.Signal(SIGTERM);
  EXPECT_EQ(daemon.Wait(5), 0);
}

// A map the daemon cannot use — here a primary-size axis of 65 values, one more than the lookup
// takes — is refused by --check-config naming the key, and at start the daemon serves without it
// (it exited: the supervisor's lookup threw). So does a map file that does not exist.
TEST(HapticsimdMaps, AMapTheLookupCannotTakeIsRefusedAndTheDaemonServesWithoutIt) {
  const Scene scene;
  const MapPoint at = PointOfScene(scene);
  std::array<std::vector<double>, kNumMapAxes> axes;
  for (int a = 0; a < kNumMapAxes; ++a) axes[a] = {at[a]};
  axes[static_cast<int>(MapAxis::kSecondaryLod)] = {2};
  axes[static_cast<int>(MapAxis::kSecondaryRate)] = {1000};
  auto& sizes = axes[static_cast<int>(MapAxis::kPrimarySize)];
  sizes.clear();
  for (int size = 1; size <= 65; ++size) sizes.push_back(size);
  ErrorMap long_axis = ErrorMap::MakeGrid(axes);
  for (MapSample& sample : long_axis.samples) {
    sample.status = SampleStatus::kOk;
    sample.max_magnitude_percent = 1.0;
  }
  const std::string map = Temp("long-axis.hsmap");
  SaveErrorMap(long_axis, map);

  const auto check = testing::RunCommand({HAPTICSIMD_PATH, "--check-config", "--error-map", map});
  EXPECT_EQ(check.exit_status, 2) << check.out << check.err;
  EXPECT_NE(check.err.find("supervisor.error_map: error map " + map +
                           " refused: "
                           "adaptivity.primary_size: a lookup axis needs 1 to 64 values"),
            std::string::npos)
      << check.err;
  const auto missing = testing::RunCommand(
      {HAPTICSIMD_PATH, "--check-config", "--error-map", Temp("no-such-map.hsmap")});
  EXPECT_EQ(missing.exit_status, 2) << missing.out;
  EXPECT_NE(missing.err.find("supervisor.error_map: "), std::string::npos) << missing.err;
  EXPECT_NE(missing.err.find("cannot open"), std::string::npos) << missing.err;

  testing::BackgroundProcess daemon({HAPTICSIMD_PATH, "--error-map", map}, Temp("long-axis.log"));
  ASSERT_NO_FATAL_FAILURE(WaitUntilServing(daemon));
  EXPECT_NE(daemon.Log().find("running without an error map"), std::string::npos) << daemon.Log();
  Client client;
  auto next = Clock::now();
  for (std::int64_t seq = 1; seq <= 300; ++seq) {
    client.Send(seq, kEdge / 2, kEdge / 2, 0.002);
    next += std::chrono::milliseconds(1);
    std::this_thread::sleep_until(next);
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  ASSERT_TRUE(daemon.running()) << daemon.Log();
  EXPECT_GT(client.Forces().size(), 250u) << daemon.Log();
  daemon.Signal(SIGTERM);
  EXPECT_EQ(daemon.Wait(5), 0) << daemon.Log();
}

// LCM off the host only when the config says so: refused by --check-config and at start, and
// when allowed, said at start as a warning. (Run inside the test's private network namespace:
// the multicast with ttl=1 reaches nothing but its loopback.)
TEST(HapticsimdConfig, AnLcmUrlThatLeavesTheHostIsRefusedUnlessAllowedAndThenSaidAloud) {
  const std::string off_host = "udpm://239.255.76.67:7667?ttl=1";
  const auto check =
      testing::RunCommand({HAPTICSIMD_PATH, "--check-config", "--lcm-url", off_host});
  EXPECT_EQ(check.exit_status, 2) << check.out << check.err;
  EXPECT_NE(check.err.find("lcm.url: ttl=1 sends LCM traffic off this host"), std::string::npos)
      << check.err;
  const auto start =
      testing::RunCommand({HAPTICSIMD_PATH, "--lcm-url", off_host, "--duration", "1"});
  EXPECT_EQ(start.exit_status, 2) << start.err;

  const std::string config = Temp("allow-network.toml");
  std::ofstream(config) << "[lcm]\nallow_network = true\nurl = \"" << off_host << "\"\n";
  testing::BackgroundProcess daemon({HAPTICSIMD_PATH, "--config", config, "--duration", "2"},
                                    Temp("allow-network.log"));
  ASSERT_NO_FATAL_FAILURE(WaitUntilServing(daemon));
  EXPECT_NE(daemon.Log().find("warning LCM traffic LEAVES THIS HOST (lcm.url = " + off_host),
            std::string::npos)
      << daemon.Log();
  EXPECT_EQ(daemon.Wait(10), 0) << daemon.Log();
}

// LCM joins its group on whatever interface the multicast route names. On a desktop that is the
// Ethernet card: machines on the LAN can then send device input to the daemon, and the systemd
// unit's IP filter (localhost only, by source address) drops local clients' packets, which carry
// the card's address. Said at start, naming the address; not said when the route is on lo. Each
// run is in a network namespace of its own, inside the test's: lo also holds 10.9.0.1, the
// source the route gives, as an Ethernet card's address would be.
TEST(HapticsimdConfig, AMulticastGroupRoutedOffLoopbackIsSaidAtStart) {
  const std::string config = Temp("multicast-route.toml");  // not /etc's, whatever it holds
  std::ofstream(config) << "[lcm]\nurl = \"udpm://239.255.76.67:7667?ttl=0\"\n";
  const std::string daemon =
      std::string("exec ") + HAPTICSIMD_PATH + " --config " + config + " --duration 1";
  const auto off = testing::RunCommand({"/usr/bin/unshare", "-rn", "/bin/sh", "-c",
                                        "ip link set lo up && ip addr add 10.9.0.1/32 dev lo && "
                                        "ip route add 224.0.0.0/4 dev lo src 10.9.0.1 && " +
                                            daemon});
  EXPECT_EQ(off.exit_status, 0) << off.err;
  EXPECT_NE(off.err.find("multicast group is routed off loopback (source address 10.9.0.1)"),
            std::string::npos)
      << off.err;
  EXPECT_NE(off.err.find("ip route replace 224.0.0.0/4 dev lo"), std::string::npos) << off.err;
  const auto on =
      testing::RunCommand({"/usr/bin/unshare", "-rn", "/bin/sh", "-c",
                           "ip link set lo up && ip route add 224.0.0.0/4 dev lo && " + daemon});
  EXPECT_EQ(on.exit_status, 0) << on.err;
  EXPECT_NE(on.err.find("serving"), std::string::npos) << on.err;
  EXPECT_EQ(on.err.find("routed off loopback"), std::string::npos) << on.err;
}

using testing::ThreadsOf;

// A flood of commands from any local process: pins at 1 kHz of a configuration whose
// verification takes many seconds (1000:999 Hz). The daemon made a thread per command (6 → 28
// threads, the primary late in 733 periods), aborted when it could not make one, and took over
// 30 s to stop. Now: no new thread, the flood refused beyond 10 commands a second and counted,
// device input still answered, and SIGTERM obeyed within 2 s.
TEST(HapticsimdCommands, AFloodOfPinsMakesNoThreadAndTheDaemonStopsWithinTwoSeconds) {
  const std::string config = Temp("command-flood.toml"), key = Temp("command-flood.key");
  std::filesystem::remove(key);
  WriteNewCommandKey(key);  // commands on LCM, switched on: signed with this key
  std::ofstream(config) << "[lcm]\naccept_commands = true\ncommand_key_file = \"" << key << "\"\n";
  testing::BackgroundProcess daemon({HAPTICSIMD_PATH, "--config", config},
                                    Temp("command-flood.log"));
  ASSERT_NO_FATAL_FAILURE(WaitUntilServing(daemon));
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  const int threads_before = ThreadsOf(daemon.pid());
  ASSERT_GT(threads_before, 0);
  Client client;
  const CommandKey signing = ReadCommandKey(key);
  command_t pin{};
  pin.command = command_t::PIN_CONFIGURATION;
  pin.primary_size = 1, pin.secondary_lod = 2, pin.secondary_rate_hz = 999;
  int most_threads = threads_before;
  auto next = Clock::now();
  for (std::int64_t k = 1; k <= 2000; ++k) {  // 2 s at 1 kHz: a pin and a device input each
    client.SignedCommand(pin, signing);
    client.Send(k, kEdge / 2, kEdge / 2, -0.002);
    if (k % 100 == 0) most_threads = std::max(most_threads, ThreadsOf(daemon.pid()));
    next += std::chrono::milliseconds(1);
    std::this_thread::sleep_until(next);
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  ASSERT_TRUE(daemon.running()) << daemon.Log();
  EXPECT_EQ(most_threads, threads_before) << "a command made a thread";
  EXPECT_GT(client.Forces().size(), 1800u) << "device input went unanswered during the flood";
  // 2,000 commands in 2 s against 10 a second: all but the burst and 10 a second (about 30)
  // refused, and counted. UDP may lose some on the way, which never arrive to be refused: the
  // device inputs sent beside them stand for what arrives, with 5 % of room for the commands'
  // larger packets (measured: 1,988 refused, 2,000 inputs received; with the rate limit's
  // refusals uncounted, 1,744).
  // A status after the flood (one each 200 ms): up to 5 s for the counts to agree, then read.
  auto refused_all_but_the_allowed = [](const status_t& s) {
    return s.commands_refused >= 0.95 * static_cast<double>(s.inputs_received) - 30;
  };
  client.WaitForStatus(refused_all_but_the_allowed, 5);
  const status_t flooded = *client.LastStatus();
  EXPECT_GE(flooded.commands_refused, 0.95 * static_cast<double>(flooded.inputs_received) - 30)
      << flooded.commands_refused << " commands refused of about " << flooded.inputs_received
      << " that arrived\n"
      << daemon.Log();
  std::printf("command flood: %lld commands refused, %lld device inputs received\n",
              static_cast<long long>(flooded.commands_refused),
              static_cast<long long>(flooded.inputs_received));
  EXPECT_NE(daemon.Log().find("command refused: more than 10 a second"), std::string::npos)
      << daemon.Log();
  const auto stop = Clock::now();
  daemon.Signal(SIGTERM);
  EXPECT_EQ(daemon.Wait(5), 0) << daemon.Log();
  EXPECT_LT(std::chrono::duration<double>(Clock::now() - stop).count(), 2.0) << daemon.Log();
}

// A command signed with the key but out of range is refused like any other, and counted: the
// status said nothing of it before (only what the signature gate and the rate limit refused was).
TEST(HapticsimdCommands, ASignedLcmCommandOutOfRangeIsRefusedAndCounted) {
  const std::string config = Temp("command-range.toml"), key = Temp("command-range.key");
  std::filesystem::remove(key);
  WriteNewCommandKey(key);
  std::ofstream(config) << "[lcm]\naccept_commands = true\ncommand_key_file = \"" << key << "\"\n";
  testing::BackgroundProcess daemon({HAPTICSIMD_PATH, "--config", config},
                                    Temp("command-range.log"));
  ASSERT_NO_FATAL_FAILURE(WaitUntilServing(daemon));
  Client client;
  ASSERT_TRUE(client.WaitForStatus([](const status_t&) { return true; }, 10)) << daemon.Log();
  const std::int64_t before = client.LastStatus()->commands_refused;
  const CommandKey signing = ReadCommandKey(key);
  command_t target{};
  target.command = command_t::SET_ERROR_TARGET;
  target.error_target_percent = 0;  // must be in (0, 100] %
  client.SignedCommand(target, signing);
  EXPECT_TRUE(
      client.WaitForStatus([&](const status_t& s) { return s.commands_refused == before + 1; }, 5))
      << daemon.Log();
  target.error_target_percent = 12;
  client.SignedCommand(target, signing);
  EXPECT_TRUE(client.WaitForStatus(
      [&](const status_t& s) {
        return s.error_target_percent == 12 && s.commands_refused == before + 1;
      },
      5))
      << daemon.Log();
}

// The shared-memory interface with a real second process: the example driver client.
TEST(HapticsimdSharedMemory, ADriverProcessGetsAForceForEveryInputAndOtherUsersAreKeptOut) {
  const std::string name = testing::PrivateSocketPath();
  const std::string config = Temp("shm.toml");
  std::ofstream(config) << "[lcm]\nenabled = false\n[shm]\nenabled = true\nsocket = \"" << name
                        << "\"\n";
  testing::BackgroundProcess daemon({HAPTICSIMD_PATH, "--config", config}, Temp("shm.log"));
  ASSERT_NO_FATAL_FAILURE(WaitUntilServing(daemon));
  struct stat info {};
  ASSERT_EQ(stat(name.c_str(), &info), 0);
  EXPECT_EQ(info.st_mode & 0777, 0660u) << "owner and group only";

  const auto result =
      testing::RunCommand({HAPTICSIM_SHM_CLIENT_PATH, "--socket", name, "--duration", "2"});
  ASSERT_EQ(result.exit_status, 0) << result.err;
  const std::string& json = result.out;
  auto number = [&json](const std::string& key) {
    const size_t at = json.find("\"" + key + "\": ");
    EXPECT_NE(at, std::string::npos) << key;
    return std::stod(json.substr(at + key.size() + 4));
  };
  // Every input is answered: by the period that first used it, from the answer's first_seq to
  // its seq (two free-running 1 kHz clocks: a period may take two inputs, and the newest is the
  // seq it answers). The rings on both sides hold 256 ms, more than a shared machine's stalls.
  EXPECT_EQ(number("inputs_answered"), 2000) << json;
  // The answer's lag behind the newest input: a few periods, but a shared machine stalls a
  // process for 30–100 ms now and then (measured here and in CI), so the bound is 150 periods; a
  // daemon that stopped answering or fell behind for good is seconds behind by the end.
  EXPECT_LE(number("max_lag_periods"), 150) << json;
  EXPECT_EQ(number("out_of_order"), 0) << json;
  EXPECT_LE(number("no_force_source_periods"), 150) << json;  // stalls only, as for the lag
  EXPECT_EQ(number("nonfinite_forces"), 0) << json;
  EXPECT_GT(number("in_contact_periods"), 1000) << json;
  EXPECT_GT(number("max_push_back_N"), 1.0) << json;  // a 1 cm press pushes back about 1.4 N

  daemon.Signal(SIGTERM);
  EXPECT_EQ(daemon.Wait(5), 0) << daemon.Log();
  EXPECT_NE(stat(name.c_str(), &info), 0) << "the socket outlived the daemon";
  const auto after = testing::RunCommand({HAPTICSIM_SHM_CLIENT_PATH, "--socket", name});
  EXPECT_EQ(after.exit_status, 2);
  EXPECT_NE(after.err.find("cannot connect to hapticsimd at " + name), std::string::npos)
      << after.err;
}

// A driver that dies mid-write leaves the input slot's sequence odd ("being written") for good:
// the daemon reads nothing more from it, flags the input stale and renders no force; a restarted
// driver is served again.
TEST(HapticsimdSharedMemory, ADriverThatDiesMidWriteExpiresTheInputAndARestartedOneIsServed) {
  const std::string name = testing::PrivateSocketPath();
  const std::string config = Temp("shm_dead.toml");
  std::ofstream(config) << "[lcm]\nenabled = false\n[shm]\nenabled = true\nsocket = \"" << name
                        << "\"\n";
  testing::BackgroundProcess daemon({HAPTICSIMD_PATH, "--config", config}, Temp("shm_dead.log"));
  ASSERT_NO_FATAL_FAILURE(WaitUntilServing(daemon));
  // Above the front face's middle, then 5 mm in, one input per millisecond; the newest answer.
  auto press = [&](shm::ShmDeviceClient& driver) {
    for (int n = 0; n < 600; ++n) {
      const double z = n < 50 ? -0.002 : std::min(0.005, 1e-5 * (n - 50));
      driver.WriteInput(n, 0, {0.125, 0.125, z});
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    shm::ShmForceOutput answer;
    EXPECT_TRUE(driver.ReadForce(&answer));
    return answer;
  };
  auto first = std::make_unique<shm::ShmDeviceClient>(name);
  const shm::ShmForceOutput pressed = press(*first);
  EXPECT_TRUE(pressed.flags & force_feedback_t::FLAG_IN_CONTACT) << pressed.flags;
  EXPECT_LT(pressed.force_n[2], -0.5);

  // It dies between the two sequence stores of its next write, before publishing it. (The slot's
  // sequence is its first word, rt/seqlock_slot.hpp: this store leaves it exactly as such a
  // death does.)
  shm::ShmSegment& view = first->segment();
  const std::int64_t next = view.newest_input.load() + 1;
  auto& sequence =
      *reinterpret_cast<std::atomic<std::uint64_t>*>(&view.inputs[next % shm::kInputSlots]);
  sequence.store(sequence.load() + 1);
  std::this_thread::sleep_for(std::chrono::milliseconds(700));  // > stale_after_s, > a session
  shm::ShmForceOutput expired;
  ASSERT_TRUE(first->ReadForce(&expired));
  EXPECT_TRUE(expired.flags & force_feedback_t::FLAG_INPUT_STALE) << expired.flags;
  EXPECT_EQ(expired.force_n[2], 0.0);

  first.reset();  // the dead driver's session ends with its process
  shm::ShmDeviceClient restarted(name);
  const shm::ShmForceOutput again = press(restarted);
  EXPECT_FALSE(again.flags & force_feedback_t::FLAG_INPUT_STALE) << again.flags;
  EXPECT_TRUE(again.flags & force_feedback_t::FLAG_IN_CONTACT) << again.flags;
  EXPECT_LT(again.force_n[2], -0.3);  // pushes back (the object had not settled: not equal)
  daemon.Signal(SIGTERM);
  EXPECT_EQ(daemon.Wait(5), 0) << daemon.Log();
}

TEST(HapticsimdSystemd, PingsTheWatchdogWhileServingNotWhileThePrimaryHangsAndSaysWhenStopping) {
  FakeSystemd systemd("notify");
  const std::string config = Temp("no-lcm.toml");
  std::ofstream(config) << "[lcm]\nenabled = false\n";
  std::unique_ptr<testing::BackgroundProcess> started = systemd.Start(config, Temp("systemd.log"));
  testing::BackgroundProcess& daemon = *started;
  std::vector<std::string>& messages = systemd.messages;
  auto receive_for = [&](double seconds, bool until_first = false) {
    systemd.ReceiveFor(seconds, until_first);
  };
  receive_for(25, true);  // startup estimates the configuration's stability first
  ASSERT_FALSE(messages.empty()) << daemon.Log();
  receive_for(1.5);  // then pings every 0.1 s
  EXPECT_EQ(messages.front().rfind("READY=1", 0), 0u) << messages.front();
  const auto pings = std::count(messages.begin(), messages.end(), "WATCHDOG=1");
  EXPECT_GE(pings, 10) << daemon.Log();

  // A hung primary loop: its thread alone stopped (ptrace stops one thread, not the process).
  // The pings stop while it hangs, so systemd would restart the daemon; they resume with it.
  const pid_t primary = ThreadOf(daemon.pid(), "hsim-primary");
  ASSERT_GT(primary, 0) << "no thread named hsim-primary in the daemon";
  ASSERT_EQ(ptrace(PTRACE_SEIZE, primary, nullptr, nullptr), 0) << std::strerror(errno);
  ASSERT_EQ(ptrace(PTRACE_INTERRUPT, primary, nullptr, nullptr), 0) << std::strerror(errno);
  int stop_status = 0;
  ASSERT_EQ(waitpid(primary, &stop_status, __WALL), primary);
  receive_for(0.2);  // a ping already on its way, or due before the loop looks, may still come
  messages.clear();
  receive_for(1.0);
  const auto hung_pings = std::count(messages.begin(), messages.end(), "WATCHDOG=1");
  ptrace(PTRACE_DETACH, primary, nullptr, nullptr);
  EXPECT_EQ(hung_pings, 0) << "the watchdog was pinged while the primary loop hung";
  messages.clear();
  receive_for(1.0);
  EXPECT_GE(std::count(messages.begin(), messages.end(), "WATCHDOG=1"), 5) << daemon.Log();
  daemon.Signal(SIGTERM);
  receive_for(1);
  EXPECT_EQ(daemon.Wait(5), 0);
  EXPECT_EQ(messages.back(), "STOPPING=1");
}

}  // namespace
}  // namespace hapticsim

namespace hapticsim {
namespace {

// `hapticsim device` against a running daemon, over both transports, as a rig would use it; and
// a recorded session replayed into it.
TEST(SimulatedDevice, DrivesTheDaemonOverLcmAndSharedMemoryAndReplaysARecordedSession) {
  const std::string name = testing::PrivateSocketPath();
  const std::string config = Temp("device.toml");
  // The segment exists, but the device input is LCM's (device.input): the shared-memory walk
  // below runs against a daemon whose input is shared memory's.
  std::ofstream(config) << "[shm]\nenabled = true\nsocket = \"" << name
                        << "\"\n[device]\ninput = \"lcm\"\n";
  testing::BackgroundProcess daemon({HAPTICSIMD_PATH, "--config", config}, Temp("device.log"));
  ASSERT_NO_FATAL_FAILURE(WaitUntilServing(daemon));
  // Record the LCM session while the device presses over LCM.
  const std::string log = Temp("session.lcmlog");
  std::filesystem::remove(log);
  testing::BackgroundProcess logger(
      {LCM_LOGGER_PATH, "--lcm-url=udpm://239.255.76.67:7667?ttl=0", "--quiet", log},
      Temp("logger.log"));
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  // A limit with room for a busy host: a quarter of the inputs may be superseded before the
  // daemon's period reads them (two free-running 1 kHz clocks). The force step is checked under
  // load by HapticsimdUnderLoad, where the load is known to be there.
  const auto lcm = testing::RunCommand({HAPTICSIM_CLI_PATH, "device", "--input", "press",
                                        "--duration", "2", "--json", "--max-unanswered", "500"});
  logger.Signal(SIGINT);
  logger.Wait(5);
  ASSERT_EQ(lcm.exit_status, 0) << lcm.out << lcm.err << daemon.Log();
  const auto report = nlohmann::json::parse(lcm.out);
  EXPECT_EQ(report["inputs_sent"], 2000);
  EXPECT_EQ(report["nonfinite_forces"], 0);
  EXPECT_EQ(report["force_out_of_contact"], 0);
  EXPECT_GT(report["contact_answers"].get<int>(), 500) << lcm.out;  // the press is in for ~0.6 s
  // Each 1 s press is the paper's (1 cm, 1 Hz): its peak is the reference run's within the
  // configuration's error and the guard's ramps (measured: 1.53 N and 1.43 N against 1.486 N).
  const auto reference = testing::RunCommand({HAPTICSIM_CLI_PATH, "simulate", "--json"});
  ASSERT_EQ(reference.exit_status, 0) << reference.err;
  const double reference_peak_n = nlohmann::json::parse(reference.out)["peak_force_N"];
  ASSERT_EQ(report["press_peaks_n"].size(), 2u) << lcm.out;
  for (const auto& peak : report["press_peaks_n"]) {
    EXPECT_NEAR(peak.get<double>(), reference_peak_n, 0.1 * reference_peak_n) << lcm.out;
  }
  // A press is smooth: the port guard's slew would allow 0.5 N per period (measured: 0.12 N).
  EXPECT_LT(report["largest_force_step_N"].get<double>(), 0.3) << lcm.out;
  // The round trip: answered within a couple of periods (measured median 1.08 ms).
  EXPECT_GT(report["latency_us"]["median"].get<double>(), 0);
  EXPECT_LT(report["latency_us"]["median"].get<double>(), 3000) << lcm.out;
  EXPECT_EQ(report["daemon"]["regions"][0]["name"], "primary");
  // The primary thread's compute time per period over the whole session: a status every 200 ms
  // (the default rate), each with its interval's percentiles.
  ASSERT_TRUE(report["daemon"]["execution"].is_array()) << lcm.out;
  ASSERT_FALSE(report["daemon"]["execution"].empty()) << lcm.out;
  const auto& primary_steps = report["daemon"]["execution"][0];
  EXPECT_EQ(primary_steps["region"], "primary") << lcm.out;
  EXPECT_GE(primary_steps["status_intervals"].get<int>(), 5) << lcm.out;
  EXPECT_GT(primary_steps["p50_median_us"].get<double>(), 0);
  EXPECT_LE(primary_steps["p50_median_us"].get<double>(),
            primary_steps["p99_interval_median_us"].get<double>());
  EXPECT_LE(primary_steps["p99_interval_median_us"].get<double>(),
            primary_steps["p99_interval_worst_us"].get<double>());
  EXPECT_NEAR(primary_steps["p50_period_share"].get<double>(),
              primary_steps["p50_median_us"].get<double>() * 1e-3, 1e-12);
  EXPECT_TRUE(report["limits_met"].get<bool>());

  // An impossible limit: the exit status says so.
  const auto strict =
      testing::RunCommand({HAPTICSIM_CLI_PATH, "device", "--duration", "1", "--max-p99-us", "1"});
  EXPECT_EQ(strict.exit_status, 4) << strict.out << strict.err;
  EXPECT_NE(strict.out.find("EXCEEDED: --max-p99-us"), std::string::npos) << strict.out;

  // The recorded session: summarised and exported (hapticsim log) ...
  ASSERT_TRUE(std::filesystem::exists(log)) << logger.Log();
  const std::string csv = Temp("session.csv");
  const auto summary =
      testing::RunCommand({HAPTICSIM_CLI_PATH, "log", log, "--json", "--csv", csv});
  ASSERT_EQ(summary.exit_status, 0) << summary.err;
  const auto recorded = nlohmann::json::parse(summary.out);
  // 2000 sent; lcm-logger, a separate process on UDP, lost 20 of them once while the machine was
  // busy (its socket buffer overflowed during a 17.7 ms gap): at most 2 % may be missing.
  EXPECT_LE(recorded["channels"]["HAPTIC_DEVICE"]["messages"].get<int>(), 2000) << summary.out;
  EXPECT_GE(recorded["channels"]["HAPTIC_DEVICE"]["messages"].get<int>(), 1960) << summary.out;
  // The rate is what the logger received over its own span, so the messages it lost and a late
  // first delivery both lower it: 979 Hz was measured once on a busy CI host with 1960+ messages.
  // What is checked is that it is a rate per second, and that with the count it gives back the
  // 2 s the device sent for.
  const double device_rate_hz = recorded["channels"]["HAPTIC_DEVICE"]["rate_hz"].get<double>();
  EXPECT_NEAR(device_rate_hz, 1000, 50) << summary.out;
  EXPECT_NEAR((recorded["channels"]["HAPTIC_DEVICE"]["messages"].get<int>() - 1) / device_rate_hz,
              2.0, 0.1)
      << summary.out;
  EXPECT_GT(recorded["channels"]["HAPTIC_FORCE"]["messages"].get<int>(), 1900);
  EXPECT_GT(recorded["forces"]["in_contact"].get<int>(), 500);
  EXPECT_GT(recorded["forces"]["magnitude_N"]["max"].get<double>(), 1.0);  // a 1 cm press
  std::ifstream rows(csv);
  std::string header;
  std::getline(rows, header);
  EXPECT_EQ(header.rfind("time_s,channel,seq,period,x_m", 0), 0u) << header;
  int lines = 0;
  for (std::string line; std::getline(rows, line);) ++lines;
  EXPECT_EQ(lines, recorded["channels"]["HAPTIC_DEVICE"]["messages"].get<int>() +
                       recorded["channels"]["HAPTIC_FORCE"]["messages"].get<int>());
  // ... and replayed into the daemon: the same press, so the same contact.
  const auto replay = testing::RunCommand({HAPTICSIM_CLI_PATH, "device", "--input", "replay",
                                           "--replay", log, "--duration", "2", "--json"});
  ASSERT_EQ(replay.exit_status, 0) << replay.out << replay.err;
  EXPECT_GT(nlohmann::json::parse(replay.out)["contact_answers"].get<int>(), 500) << replay.out;

  const auto missing = testing::RunCommand(
      {HAPTICSIM_CLI_PATH, "device", "--input", "replay", "--replay", Temp("nothing.lcmlog")});
  EXPECT_EQ(missing.exit_status, 2);
  EXPECT_NE(missing.err.find("cannot open it as an LCM log"), std::string::npos) << missing.err;
  daemon.Signal(SIGTERM);
  EXPECT_EQ(daemon.Wait(5), 0) << daemon.Log();

  const std::string shm_config = Temp("device-shm.toml");
  std::ofstream(shm_config) << "[shm]\nenabled = true\nsocket = \"" << name << "\"\n";
  testing::BackgroundProcess shm_daemon({HAPTICSIMD_PATH, "--config", shm_config},
                                        Temp("device-shm.log"));
  ASSERT_NO_FATAL_FAILURE(WaitUntilServing(shm_daemon));
  // Shared memory, a seeded random walk: every daemon answer reaches the device.
  const auto shm = testing::RunCommand({HAPTICSIM_CLI_PATH, "device", "--transport", "shm",
                                        "--shm-socket", name, "--input", "walk", "--seed", "7",
                                        "--duration", "3", "--json", "--max-lost", "0"});
  EXPECT_EQ(shm.exit_status, 0) << shm.out << shm.err;
  const auto walk = nlohmann::json::parse(shm.out);
  EXPECT_EQ(walk["lost_answers"], 0);
  EXPECT_EQ(walk["duplicated_answers"], 0);
  EXPECT_GT(walk["contact_answers"].get<int>(), 100) << shm.out;

  shm_daemon.Signal(SIGTERM);
  EXPECT_EQ(shm_daemon.Wait(5), 0) << shm_daemon.Log();
}

// Accuracy under load, as on a user's desktop: ten 1 cm presses at 1 Hz over LCM, first on a quiet
// machine, then with two busy threads at normal priority beside the daemon (no real-time
// privileges). Every press's peak stays within 10 % of the same press's quiet peak — a guard that
// clamped the force to zero, or a coupling that ran away, would fail — and the force never steps
// by more than half the device's slew ceiling.
TEST(HapticsimdUnderLoad, TenPressesKeepTheirPeaksWithTwoBusyThreadsBeside) {
  testing::BackgroundProcess daemon({HAPTICSIMD_PATH}, Temp("load.log"));
  ASSERT_NO_FATAL_FAILURE(WaitUntilServing(daemon));
  auto presses = [&](const char* load) {
    const auto run = testing::RunCommand({HAPTICSIM_CLI_PATH, "device", "--input", "press",
                                          "--duration", "10", "--cpu-load", load, "--json"});
    EXPECT_EQ(run.exit_status, 0) << run.out << run.err;
    return nlohmann::json::parse(run.out);
  };
  const auto quiet = presses("0");
  const auto loaded = presses("2");
  ASSERT_EQ(quiet["press_peaks_n"].size(), 10u) << quiet.dump();
  ASSERT_EQ(loaded["press_peaks_n"].size(), 10u) << loaded.dump();
  for (int k = 0; k < 10; ++k) {
    const double q = quiet["press_peaks_n"][k], l = loaded["press_peaks_n"][k];
    EXPECT_GT(q, 1.3) << "press " << k;  // the default scene's 1 cm press: about 1.43–1.53 N
    EXPECT_NEAR(l, q, 0.1 * q) << "press " << k << "\nquiet " << quiet.dump() << "\nloaded "
                               << loaded.dump();
  }
  // The load was there: its two threads were given CPU time (about 17 s of the 20 s two cores had,
  // measured; a run's latencies are no proof, since a noisy machine moves the quiet run's too).
  EXPECT_GT(loaded["cpu_load"]["cpu_s"].get<double>(), 3.0) << loaded.dump();
  EXPECT_EQ(quiet["cpu_load"]["cpu_s"].get<double>(), 0.0);
  EXPECT_EQ(loaded["nonfinite_forces"], 0);
  EXPECT_EQ(loaded["force_out_of_contact"], 0);
  // No step either: late input and late periods are placed on the device's timeline and a tip
  // that still jumps is caught up with (0.04–0.11 N measured in 8 loaded runs, most of it the
  // touch-down itself, which steps 0.10–0.12 N on a quiet machine too; 0.18–0.40 N when a burst
  // of late inputs could push the tip ahead and a 48 µm jump went through).
  EXPECT_LT(loaded["max_force_step_in_contact_n"].get<double>(), 0.25) << loaded.dump();
  std::printf("loaded press peaks (N):");
  for (const auto& peak : loaded["press_peaks_n"]) std::printf(" %.3f", peak.get<double>());
  std::printf("; largest step in contact %.3f N\n",
              loaded["max_force_step_in_contact_n"].get<double>());
  daemon.Signal(SIGTERM);
  EXPECT_EQ(daemon.Wait(5), 0) << daemon.Log();
}

// What a device's --trace says about a stroke (--input stroke at --frequency 0.5) from its second
// stroke on (a new session's first inputs reuse seqs the daemon took from the last session, which
// it refuses until it sees the device restarted): in the middle of every slide (a phase of 0.35 to
// 0.6 of the period) the ratio of the lateral force to the normal and the mean normal force, and
// the largest force step between answers in contact.
struct SlideTrace {
  double lowest_ratio = 1e9, highest_ratio = 0, mean_normal_n = 0, largest_step_n = 0;
  int periods = 0;
};
SlideTrace ReadSlides(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);  // the header
  SlideTrace slides;
  double normal_sum = 0;
  std::array<double, 9> last{};
  while (std::getline(in, line)) {
    std::array<double, 9> v{};
    if (std::sscanf(line.c_str(), "%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf", &v[0], &v[1], &v[2], &v[3],
                    &v[4], &v[5], &v[6], &v[7], &v[8]) != 9 ||
        v[0] < 2.0) {
      continue;
    }
    if (v[7] == 1 && last[7] == 1) {
      slides.largest_step_n = std::max(slides.largest_step_n,
                                       std::hypot(v[4] - last[4], v[5] - last[5], v[6] - last[6]));
    }
    last = v;
    const double phase = std::fmod(v[0] * 0.5, 1.0);
    const double normal = -v[6], lateral = std::hypot(v[4], v[5]);
    if (phase < 0.35 || phase > 0.6 || v[7] != 1 || normal < 0.05) continue;
    slides.lowest_ratio = std::min(slides.lowest_ratio, lateral / normal);
    slides.highest_ratio = std::max(slides.highest_ratio, lateral / normal);
    normal_sum += normal;
    ++slides.periods;
  }
  if (slides.periods > 0) slides.mean_normal_n = normal_sum / slides.periods;
  return slides;
}

// A tool that slides (contact.model = "proxy", μ_s 0.5, μ_k 0.4), served by hapticsimd over LCM to
// the simulated device's palpation stroke — 5 mm in, 60 mm along the face, out and back, four
// times (the last three judged, see SlideTrace) — first on a quiet machine, then with two busy
// threads beside the daemon (no real-time privileges). Both times: the primary region follows the
// proxy across the face (the daemon's log names each node it moved to); once sliding, the lateral
// force is μ_k times the normal within 5 %; it never exceeds μ_s times it; the force never steps by
// more than 0.1 N between periods; and the loaded stroke presses as hard as the quiet one (a guard
// that zeroed the force would fail that). The supervisor's map offers primary sizes 1 and 3: a
// sliding tool's proxy needs 2 at least, so 3 runs.
TEST(HapticsimdSlidingTool, AStrokeSlidesAtKineticFrictionAndTheRegionsFollowItUnderLoad) {
  const std::string scene = Temp("proxy_scene.toml"), config = Temp("proxy.toml");
  std::ofstream(scene) << "[contact]\nmodel = \"proxy\"\nstatic_friction = 0.5\n"
                          "kinetic_friction = 0.4\n[adaptivity]\nprimary_size = 3\n";
  std::ofstream(config) << "[scene]\nfile = \"" << scene << "\"\n[supervisor]\nerror_map = \""
                        << SmallMap() << "\"\nerror_target_percent = 7.0\n";
  testing::BackgroundProcess daemon({HAPTICSIMD_PATH, "--config", config}, Temp("proxy.log"));
  ASSERT_NO_FATAL_FAILURE(WaitUntilServing(daemon));
  auto stroke = [&](const std::string& load) {
    const std::string trace = Temp("stroke_" + load + ".csv");
    const auto run = testing::RunCommand({HAPTICSIM_CLI_PATH,
                                          "device",
                                          "--scene",
                                          scene,
                                          "--input",
                                          "stroke",
                                          "--amplitude",
                                          "0.005",
                                          "--length",
                                          "0.06",
                                          "--frequency",
                                          "0.5",
                                          "--at",
                                          "0.09,0.125",
                                          "--duration",
                                          "8",
                                          "--cpu-load",
                                          load,
                                          "--trace",
                                          trace,
                                          "--json"});
    EXPECT_EQ(run.exit_status, 0) << run.out << run.err;
    return std::pair{nlohmann::json::parse(run.out), ReadSlides(trace)};
  };
  const auto [quiet, quiet_slides] = stroke("0");
  const auto [loaded, loaded_slides] = stroke("2");
  EXPECT_GT(loaded["cpu_load"]["cpu_s"].get<double>(), 3.0) << loaded.dump();
  for (const auto& [report, slides] : {std::pair{quiet, quiet_slides}, {loaded, loaded_slides}}) {
    const std::string what = report["cpu_load"].dump();
    EXPECT_EQ(report["daemon"]["primary_size"], 3) << what;
    EXPECT_EQ(report["lost_answers"], 0) << what;
    EXPECT_EQ(report["nonfinite_forces"], 0) << what;
    EXPECT_EQ(report["force_out_of_contact"], 0) << what;
    EXPECT_GT(report["contact_answers"].get<int>(), 4000) << what;
    EXPECT_LE(report["max_lateral_to_normal"].get<double>(), 0.5 * 1.05) << what;
    EXPECT_LT(slides.largest_step_n, 0.1) << what;
    EXPECT_GT(slides.periods, 1200) << what;
    EXPECT_GE(slides.lowest_ratio, 0.4 * 0.95) << what;
    EXPECT_LE(slides.highest_ratio, 0.4 * 1.05) << what;
    EXPECT_GT(slides.mean_normal_n, 0.3) << what;
    // Every answer in contact said how wrong it is: the map's error where the regions were,
    // within the target the supervisor chose for.
    const nlohmann::json& error = report["error_percent_in_contact"];
    EXPECT_EQ(error["answers_without"], 0) << what;
    EXPECT_GT(error["lowest"].get<double>(), 0.0) << what;
    EXPECT_LE(error["lowest"].get<double>(), error["highest"].get<double>()) << what;
    EXPECT_LE(error["highest"].get<double>(), 7.0) << what;
    std::printf(
        "stroke with %s: lateral/normal %.4f … %.4f while sliding, normal %.3f N, largest "
        "step %.4f N, %d late answers\n",
        what.c_str(), slides.lowest_ratio, slides.highest_ratio, slides.mean_normal_n,
        slides.largest_step_n, report["late_answers"].get<int>());
  }
  EXPECT_NEAR(loaded_slides.mean_normal_n, quiet_slides.mean_normal_n,
              0.05 * quiet_slides.mean_normal_n);
  daemon.Signal(SIGTERM);
  EXPECT_EQ(daemon.Wait(5), 0) << daemon.Log();
  // The regions followed the proxy: nodes 5, 6 and 7 along the slide, on each of the 8 strokes.
  const std::string log = daemon.Log();
  int moves = 0;
  for (std::size_t at = 0;
       (at = log.find("regions centred on contact node (7, 6, 0)", at)) != std::string::npos;
       ++at) {
    ++moves;
  }
  EXPECT_GE(moves, 8) << log;
}

// One owner of the device input: with shared memory owning it, a process that publishes device
// input on LCM changes nothing the shared-memory driver feels, and is refused and counted.
TEST(HapticsimdInputOwner, LcmInputIsRefusedWhileSharedMemoryOwnsTheInput) {
  const std::string name = testing::PrivateSocketPath();
  const std::string config = Temp("owner.toml");
  std::ofstream(config) << "[shm]\nenabled = true\nsocket = \"" << name << "\"\n";
  testing::BackgroundProcess daemon({HAPTICSIMD_PATH, "--config", config}, Temp("owner.log"));
  ASSERT_NO_FATAL_FAILURE(WaitUntilServing(daemon));
  Client intruder;
  ASSERT_TRUE(intruder.WaitForStatus([](const status_t& s) { return s.input_owner == "shm"; }, 10))
      << daemon.Log();
  shm::ShmDeviceClient driver(name);
  // The driver holds the tool 5 mm in; the intruder publishes a tip 2 cm in at the same time.
  std::vector<double> forces_z;
  std::int64_t seq = 1;
  auto drive = [&](int periods, double z, bool intrude) {
    for (int n = 0; n < periods; ++n, ++seq) {
      driver.WriteInput(seq, seq * 1000, {kEdge / 2, kEdge / 2, z});
      if (intrude) intruder.Send(seq, kEdge / 2, kEdge / 2, 0.02);
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
      shm::ShmForceOutput out;
      if (driver.ReadForce(&out)) forces_z.push_back(out.force_n[2]);
    }
  };
  drive(50, -0.002, false);
  for (int n = 0; n < 500; ++n) drive(1, -0.002 + 0.007 * n / 500.0, false);
  drive(700, 0.005, false);
  const double held = forces_z.back();
  forces_z.clear();
  drive(700, 0.005, true);
  ASSERT_FALSE(forces_z.empty());
  ASSERT_LT(held, -0.2);  // 5 mm in pushes back
  // The tissue relaxes slowly under the held tool (a few % over the phase); the intruder's 2 cm
  // would have pushed back several times harder.
  for (double f : forces_z) {
    EXPECT_LE(std::abs(f), std::abs(held) + 0.005);
    EXPECT_GE(std::abs(f), 0.85 * std::abs(held));
  }
  ASSERT_TRUE(
      intruder.WaitForStatus([](const status_t& s) { return s.inputs_wrong_transport >= 500; }, 5))
      << daemon.Log();
  EXPECT_NE(daemon.Log().find("device input on LCM refused: shared memory owns the input"),
            std::string::npos)
      << daemon.Log();
  daemon.Signal(SIGTERM);
  EXPECT_EQ(daemon.Wait(5), 0) << daemon.Log();
}

}  // namespace
}  // namespace hapticsim
