// Liveness (issue "Hostile neighbours", points 7 and 8): a driver always knows whether a daemon
// computes its force, and the daemon knows whether each thread the force depends on runs. The
// daemon is killed, or one of its threads stopped alone (ptrace), from this separate process.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/ptrace.h>
#include <sys/wait.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <fstream>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "hapticsim/force_feedback_t.hpp"
#include "ipc/shm_device_client.hpp"
#include "tests/security/hostile_neighbour.hpp"
#include "tests/support/fake_systemd.hpp"

namespace hapticsim {
namespace {

using security::Temp;
using testing::FakeSystemd;
using testing::ThreadOf;
using testing::WaitUntilServing;

// A daemon killed outright (SIGKILL: nothing cleaned up) leaves its last answer in the segment,
// in contact, and the client read that frozen force as long as it liked. Now the client says
// "no force source" within 10 ms of the daemon's last answer, and maps the segment a restarted
// daemon makes, by itself, and is served by it.
TEST(Liveness, AClientSeesNoForceSourceWithin10msOfAKilledDaemonAndReconnects) {
  const std::string name = testing::PrivateSocketPath();
  const std::string config = Temp("shm_killed.toml");
  std::ofstream(config) << "[lcm]\nenabled = false\n[shm]\nenabled = true\nsocket = \"" << name
                        << "\"\n";
  auto now_ns = [] {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(
               std::chrono::steady_clock::now().time_since_epoch())
        .count();
  };
  std::int64_t seq = 0;
  auto press = [&](shm::ShmDeviceClient& driver, int periods) {
    for (int n = 0; n < periods; ++n, ++seq) {
      const double z = n < 50 ? -0.002 : std::min(0.005, 1e-5 * (n - 50));
      driver.WriteInput(seq, 0, {0.125, 0.125, z});
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  };
  auto daemon = std::make_unique<testing::BackgroundProcess>(
      std::vector<std::string>{HAPTICSIMD_PATH, "--config", config}, Temp("shm_killed.log"));
  ASSERT_NO_FATAL_FAILURE(WaitUntilServing(*daemon));
  shm::ShmDeviceClient driver(name);
  press(driver, 400);
  EXPECT_EQ(driver.Source(now_ns()), shm::ForceSource::kLive);
  shm::ShmForceOutput pressed;
  ASSERT_TRUE(driver.ReadForce(&pressed));
  EXPECT_TRUE(pressed.flags & force_feedback_t::FLAG_IN_CONTACT) << pressed.flags;

  const auto killed = std::chrono::steady_clock::now();
  daemon->Signal(SIGKILL);
  daemon->Wait(5);
  double none_after_ms = -1;
  for (int n = 0; n < 100 && none_after_ms < 0; ++n) {  // the driver goes on writing
    driver.WriteInput(seq++, 0, {0.125, 0.125, 0.005});
    if (driver.Source(now_ns()) == shm::ForceSource::kNone) {
      none_after_ms =
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - killed)
              .count();
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  ASSERT_GE(none_after_ms, 0) << "still a force source 100 ms after the daemon was killed";
  EXPECT_LT(none_after_ms, 15.0);  // 10 ms after its last answer, and the kill's own latency
  shm::ShmForceOutput frozen;
  EXPECT_TRUE(driver.ReadForce(&frozen));  // the last answer is still there to read …
  EXPECT_TRUE(frozen.flags & force_feedback_t::FLAG_IN_CONTACT);  // … in contact: hence Source
  EXPECT_FALSE(driver.Reconnect()) << "nothing new to connect to yet";

  daemon = std::make_unique<testing::BackgroundProcess>(
      std::vector<std::string>{HAPTICSIMD_PATH, "--config", config}, Temp("shm_killed2.log"));
  ASSERT_NO_FATAL_FAILURE(WaitUntilServing(*daemon));
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  bool reconnected = false;
  while (!reconnected && std::chrono::steady_clock::now() < deadline) {
    reconnected = driver.Reconnect();
    if (!reconnected) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ASSERT_TRUE(reconnected);
  press(driver, 700);  // the driver's seq goes on: the new daemon takes it as a new session
  EXPECT_EQ(driver.Source(now_ns()), shm::ForceSource::kLive);
  shm::ShmForceOutput again;
  ASSERT_TRUE(driver.ReadForce(&again));
  EXPECT_TRUE(again.flags & force_feedback_t::FLAG_IN_CONTACT) << again.flags;
  EXPECT_LT(again.force_n[2], -0.3);
  daemon->Signal(SIGTERM);
  EXPECT_EQ(daemon->Wait(5), 0) << daemon->Log();
}

// The health check covers every thread the force depends on. A stalled I/O thread (no force
// reaches the device) stops the watchdog pings and is named; a stalled secondary is named while
// the primary renders around it, and the pings go on (systemd would otherwise restart a daemon
// whose force is still computed and sent).
TEST(Liveness, AStalledIoThreadStopsThePingsAndAStalledSecondaryIsNamed) {
  FakeSystemd systemd("notify-health");
  const std::string config = Temp("health.toml");
  // Awake at rest, so the secondary is expected to run.
  std::ofstream(config) << "[lcm]\nenabled = false\n[realtime]\nsleep_at_rest = false\n";
  std::unique_ptr<testing::BackgroundProcess> started = systemd.Start(config, Temp("health.log"));
  testing::BackgroundProcess& daemon = *started;
  std::vector<std::string>& messages = systemd.messages;
  auto receive_for = [&](double seconds, bool until_first = false) {
    systemd.ReceiveFor(seconds, until_first);
  };
  auto count = [&](const std::string& message) { return systemd.Count(message); };
  // Stops `thread` alone; the messages of the `seconds` after the first 0.7 s (the health
  // check calls a thread stalled after 0.5 s of silence; a ping already on its way may come).
  auto stopped_for = [&](const std::string& thread, double seconds) {
    const pid_t tid = ThreadOf(daemon.pid(), thread);
    EXPECT_GT(tid, 0) << "no thread named " << thread;
    if (tid <= 0) return;
    EXPECT_EQ(ptrace(PTRACE_SEIZE, tid, nullptr, nullptr), 0) << std::strerror(errno);
    EXPECT_EQ(ptrace(PTRACE_INTERRUPT, tid, nullptr, nullptr), 0) << std::strerror(errno);
    int stop_status = 0;
    EXPECT_EQ(waitpid(tid, &stop_status, __WALL), tid);
    receive_for(0.7);
    messages.clear();
    receive_for(seconds);
    ptrace(PTRACE_DETACH, tid, nullptr, nullptr);
  };
  receive_for(25, true);
  ASSERT_FALSE(messages.empty()) << daemon.Log();
  receive_for(1.0);

  stopped_for("hsim-io", 1.5);
  EXPECT_EQ(count("WATCHDOG=1"), 0) << "pinged while no force could reach the device";
  messages.clear();
  receive_for(1.0);
  EXPECT_GE(count("WATCHDOG=1"), 5) << "the pings did not resume with the thread";
  EXPECT_GE(count("STATUS=serving"), 1);

  stopped_for("hsim-region1", 1.5);
  EXPECT_GE(count("WATCHDOG=1"), 8) << "a stalled secondary stopped the pings";
  // Named in the log and in systemd's status line (systemctl status), each.
  EXPECT_NE(daemon.Log().find("health: stalled: I/O (hsim-io)"), std::string::npos);
  EXPECT_NE(daemon.Log().find("; the systemd watchdog is not pinged"), std::string::npos);
  EXPECT_NE(daemon.Log().find("health: stalled: secondary (hsim-region1)"), std::string::npos)
      << daemon.Log();
  daemon.Signal(SIGTERM);
  EXPECT_EQ(daemon.Wait(5), 0) << daemon.Log();
}

}  // namespace
}  // namespace hapticsim
