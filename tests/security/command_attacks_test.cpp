// Hostile neighbours on the command channels (issue "Hostile neighbours", points 2 and 4): any
// local process could RESET the simulation, pin a configuration or change the error target over
// LCM. Now state-changing commands come from the control socket (hapticsim ctl), from root, the
// daemon's user and control.group only; LCM commands are refused unless lcm.accept_commands.
#include <grp.h>
#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <lcm/lcm-cpp.hpp>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "core/error.hpp"
#include "hapticsim/command_t.hpp"
#include "ipc/command_signature.hpp"
#include "ipc/control_client.hpp"
#include "ipc/unique_fd.hpp"
#include "tests/security/hostile_neighbour.hpp"

namespace hapticsim {
namespace {

using security::Clock;
using security::ExitStatusOf;
using security::HostileNeighbour;
using security::kWindow;
using security::MissBound;
using security::Spawn;

// Any local process on the bus: RESET and pins at 100 Hz for the attacked window.
TEST_F(HostileNeighbour, CommandsOnLcmAreRefusedByDefaultAndCounted) {
  const std::int64_t quiet = MissesOver(Quiet);
  const status_t before = *monitor_.LastStatus();
  pid_t attacker = -1;
  const std::int64_t attacked = MissesOver([&] {
    attacker = Spawn([] {
      lcm::LCM bus("udpm://239.255.76.67:7667?ttl=0");
      if (!bus.good()) return 10;
      command_t reset{}, pin{};
      reset.command = command_t::RESET;
      pin.command = command_t::PIN_CONFIGURATION;
      pin.primary_size = 3, pin.secondary_lod = 2, pin.secondary_rate_hz = 1000;
      const auto end = Clock::now() + kWindow;
      for (int k = 0; Clock::now() < end; ++k) {
        bus.publish("HAPTIC_COMMAND", k % 2 ? &reset : &pin);
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
      }
      return 0;
    });
    std::this_thread::sleep_for(kWindow + std::chrono::milliseconds(100));
  });
  ASSERT_EQ(ExitStatusOf(attacker), 0);
  ASSERT_TRUE(daemon_->running()) << daemon_->Log();
  EXPECT_LE(attacked, MissBound(quiet)) << "quiet: " << quiet;
  ASSERT_TRUE(
      monitor_.WaitForStatus([](const status_t& s) { return s.commands_refused >= 100; }, 2))
      << daemon_->Log();
  const status_t after = *monitor_.LastStatus();
  EXPECT_EQ(after.reconfigurations, before.reconfigurations) << "a RESET or a pin went through";
  EXPECT_FALSE(after.pinned);
  EXPECT_NE(daemon_->Log().find("refused: lcm.accept_commands is false (use hapticsim ctl)"),
            std::string::npos)
      << daemon_->Log();
  // The authorised channel still works: this test runs as the daemon's user.
  EXPECT_EQ(shm::SendControlRequest(control_, "reset", 5000),
            "ok: the simulation restarts from rest");
  EXPECT_TRUE(monitor_.WaitForStatus(
      [&](const status_t& s) { return s.reconfigurations > before.reconfigurations; }, 2));
}

// Commands on LCM switched on (lcm.accept_commands, lcm.command_key_file): the daemon takes only
// commands signed with its key, fresh, and each once. The attacker on the bus sends unsigned
// commands, commands signed with its own key, and plays back every command it overhears, as it
// was and with a field changed. The operator's `hapticsim ctl --lcm` gets through, once.
class SignedLcmCommands : public HostileNeighbour {
 protected:
  std::string MoreLcmKeys() override {
    if (key_.empty()) {  // one key for the daemon's life
      key_ = security::Temp(Name() + ".key");
      std::filesystem::remove(key_);
      WriteNewCommandKey(key_);
    }
    return "accept_commands = true\ncommand_key_file = \"" + key_ + "\"\n";
  }
  std::string key_;
};

TEST_F(SignedLcmCommands, OnlyFreshCommandsSignedWithTheKeyAreTakenAndEachOnce) {
  const std::int64_t quiet = MissesOver(Quiet);
  const status_t before = *monitor_.LastStatus();
  pid_t attacker = -1;
  testing::CommandResult reset, target;
  const std::int64_t attacked = MissesOver([&] {
    attacker = Spawn([] {
      lcm::LCM bus("udpm://239.255.76.67:7667?ttl=0");
      if (!bus.good()) return 10;
      // What it hears of others (the operator's commands), once each, by utime: not its own
      // forgeries, nor its own changed copies of what it heard.
      struct Ear {
        std::set<std::int64_t> sent_or_heard;
        std::vector<command_t> heard;
        void On(const lcm::ReceiveBuffer*, const std::string&, const command_t* c) {
          if (sent_or_heard.insert(c->utime).second) heard.push_back(*c);
        }
      } ear;
      bus.subscribe("HAPTIC_COMMAND", &Ear::On, &ear);
      CommandKey own{};  // the attacker's key: not the daemon's
      own.fill(0x5a);
      command_t reset{};
      reset.command = command_t::RESET;
      int replays = 0;
      auto hear = [&bus] {
        while (bus.handleTimeout(0) > 0) {
        }
      };
      // The window, and until both of the operator's commands were heard (they may come late on
      // a loaded machine; 10 s at most).
      const auto end = Clock::now() + kWindow, latest = Clock::now() + std::chrono::seconds(10);
      for (int k = 0; (Clock::now() < end || ear.heard.size() < 2) && Clock::now() < latest; ++k) {
        hear();
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
        command_t forged = reset;
        forged.utime = CommandClockUs();
        ear.sent_or_heard.insert(forged.utime);
        if (k % 2) SignCommand(&forged, "HAPTIC_COMMAND", own);
        bus.publish("HAPTIC_COMMAND", &forged);
        for (const command_t& heard : ear.heard) {
          command_t again = heard;
          bus.publish("HAPTIC_COMMAND", &again);  // as heard
          again.error_target_percent = 50;        // and changed, the MAC kept
          bus.publish("HAPTIC_COMMAND", &again);
          ++replays;
        }
      }
      // Once more after a pause, the newest command heard as it was: the last refusal, so the
      // daemon's rate-limited log names it.
      std::this_thread::sleep_for(std::chrono::milliseconds(300));
      hear();
      if (ear.heard.size() != 2) return 11;  // the operator's RESET and target, nothing else
      bus.publish("HAPTIC_COMMAND", &ear.heard.back());
      return replays > 0 ? 0 : 12;
    });
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    reset = testing::RunCommand({HAPTICSIM_PATH, "ctl", "--lcm", "--key-file", key_, "reset"});
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    target = testing::RunCommand(
        {HAPTICSIM_PATH, "ctl", "--lcm", "--key-file", key_, "set-error-target", "12"});
    std::this_thread::sleep_for(kWindow);
  });
  ASSERT_EQ(reset.exit_status, 0) << reset.err;
  ASSERT_EQ(target.exit_status, 0) << target.err;
  EXPECT_NE(reset.out.find("sent, signed, on HAPTIC_COMMAND"), std::string::npos) << reset.out;
  ASSERT_EQ(ExitStatusOf(attacker), 0) << "the attacker did not overhear the operator's two";
  ASSERT_TRUE(daemon_->running()) << daemon_->Log();
  EXPECT_LE(attacked, MissBound(quiet)) << "quiet: " << quiet;
  ASSERT_TRUE(monitor_.WaitForStatus(
      [](const status_t& s) { return s.error_target_percent == 12 && s.commands_refused >= 50; },
      2))
      << daemon_->Log();
  const status_t after = *monitor_.LastStatus();
  EXPECT_EQ(after.reconfigurations - before.reconfigurations, 1)
      << "the operator's RESET once, and none of the attacker's or of its replays";
  // The RESET woke the sleeping regions within a supervisor tick: that is not a stall since the
  // regions went to sleep (the health check said so, 2.2 s, until it read the wake first).
  EXPECT_EQ(daemon_->Log().find("health: stalled"), std::string::npos) << daemon_->Log();
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // the last replay's log line
  const std::string log = daemon_->Log();
  for (const char* said : {"accepted when signed with the key in", "signature does not match",
                           "refused: taken before: a replay"}) {
    EXPECT_NE(log.find(said), std::string::npos) << said << "\n" << log;
  }
}

// Even with the control socket opened to everyone by mistake, another user is refused: the
// daemon asks the kernel who connected.
TEST_F(HostileNeighbour, AUserOutsideTheControlGroupCannotCommandTheDaemon) {
  if (geteuid() != 0) GTEST_SKIP() << "needs root, to be another user";
  ASSERT_EQ(chmod(control_.c_str(), 0666), 0);
  ASSERT_EQ(chmod(std::filesystem::path(control_).parent_path().c_str(), 0755), 0);
  const std::int64_t quiet = MissesOver(Quiet);
  const status_t before = *monitor_.LastStatus();
  std::int64_t attacked = 0;
  const int outsider_status = AttackAsAnotherUser(
      [&] {
        int refused = 0;
        for (const char* request : {"reset", "pin 3 2 1000", "set-error-target 50", "release"}) {
          try {
            const std::string answer = shm::SendControlRequest(control_, request, 2000);
            if (answer.find("(uid 65534) is not in group") != std::string::npos) ++refused;
          } catch (const Error&) {
          }
        }
        return refused == 4 ? 0 : 1;
      },
      &attacked);
  if (outsider_status == kNoOtherUser)
    GTEST_SKIP() << "uid 65534 is not available here (user namespace)";
  EXPECT_EQ(outsider_status, 0) << "a request was not refused by name";
  ASSERT_TRUE(daemon_->running()) << daemon_->Log();
  EXPECT_LE(attacked, MissBound(quiet)) << "quiet: " << quiet;
  ASSERT_TRUE(monitor_.WaitForStatus([](const status_t& s) { return s.commands_refused == 4; }, 2))
      << daemon_->Log();
  const status_t after = *monitor_.LastStatus();
  EXPECT_EQ(after.reconfigurations, before.reconfigurations);
  EXPECT_EQ(after.error_target_percent, before.error_target_percent);
  EXPECT_NE(daemon_->Log().find("control socket: refused pid"), std::string::npos)
      << daemon_->Log();
}

// Point 2, through the control socket: a flood of connections that say nothing and of pins
// whose verification takes seconds (1000:999 Hz). At most ControlServer::kMaxPending wait, the
// rest are refused and counted; no request makes a thread; a driver is still served; and the
// daemon stops within 2 s.
TEST_F(HostileNeighbour, AFloodOfControlRequestsMakesNoThreadAndTheDaemonStopsWithinTwoSeconds) {
  const std::int64_t quiet = MissesOver(Quiet);
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  const int threads_before = testing::ThreadsOf(daemon_->pid());
  ASSERT_GT(threads_before, 0);
  int most_threads = threads_before;
  std::int64_t longest_status_gap_us = 0;
  pid_t flooder = -1;
  const std::int64_t attacked = MissesOver([&] {
    flooder = Spawn([&] {
      std::vector<shm::UniqueFd> silent;  // held open for the window, never asking anything
      for (int k = 0; k < 32; ++k) {
        shm::UniqueFd connection(socket(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0));
        sockaddr_un address{};
        address.sun_family = AF_UNIX;
        std::snprintf(address.sun_path, sizeof address.sun_path, "%s", control_.c_str());
        if (connect(connection.get(), reinterpret_cast<sockaddr*>(&address), sizeof address) == 0) {
          silent.push_back(std::move(connection));
        }
      }
      int answered = 0;
      const auto end = Clock::now() + kWindow;
      while (Clock::now() < end) {
        try {
          shm::SendControlRequest(control_, "pin 1 2 999", 2000);
          ++answered;
        } catch (const Error&) {
        }
      }
      return answered > 0 ? 0 : 1;
    });
    // The supervisor keeps ticking through the flood: its status (20 a second) keeps coming.
    std::int64_t last_utime = monitor_.LastStatus()->utime;
    for (int k = 0; k < 32; ++k) {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      most_threads = std::max(most_threads, testing::ThreadsOf(daemon_->pid()));
      const std::int64_t utime = monitor_.LastStatus()->utime;
      longest_status_gap_us = std::max(longest_status_gap_us, utime - last_utime);
      last_utime = utime;
    }
  });
  EXPECT_EQ(ExitStatusOf(flooder), 0) << "no request of the flood was answered at all";
  ASSERT_TRUE(daemon_->running()) << daemon_->Log();
  EXPECT_EQ(most_threads, threads_before) << "a request made a thread";
  // A supervisor held in the flood would also hold back the watchdog: systemd restarts at 2 s.
  EXPECT_LT(longest_status_gap_us, 500'000) << "the supervisor stopped ticking in the flood";
  EXPECT_LE(attacked, MissBound(quiet)) << "quiet: " << quiet;
  ASSERT_TRUE(monitor_.WaitForStatus([](const status_t& s) { return s.commands_refused >= 10; }, 2))
      << daemon_->Log();
  ExpectADriverIsServed();
  const auto stop = Clock::now();
  daemon_->Signal(SIGTERM);
  EXPECT_EQ(daemon_->Wait(5), 0) << daemon_->Log();
  EXPECT_LT(std::chrono::duration<double>(Clock::now() - stop).count(), 2.0) << daemon_->Log();
}

}  // namespace
}  // namespace hapticsim
