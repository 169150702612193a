// Config ceilings at a running daemon (issue "Hostile neighbours", point 6): whoever can write the
// config file, or a mistake in it, and a SIGHUP from another process. A force ceiling of 1e300 N,
// an LCM URL that would send off the host, a speed limit of 1e300 m/s were all accepted; now each
// reload is refused, naming the key, and the daemon serves on as it was configured.
#include <gtest/gtest.h>
#include <signal.h>

#include <string>
#include <thread>

#include "tests/security/hostile_neighbour.hpp"

namespace hapticsim {
namespace {

using security::ExitStatusOf;
using security::HostileNeighbour;
using security::MissBound;
using security::Spawn;

TEST_F(HostileNeighbour, AHostileConfigIsRefusedOnReloadAndTheDaemonServesOnAsConfigured) {
  const std::int64_t quiet = MissesOver(Quiet);
  const status_t before = *monitor_.LastStatus();
  struct Attempt {
    std::string lcm_url, tables, refusal;
  };
  const std::string host = "udpm://239.255.76.67:7667?ttl=0";
  const Attempt attempts[] = {
      {host, "[device]\nmax_force_n = 1e300\n", "device.max_force_n must be"},
      {"udpm://239.255.76.67:7667?ttl=255", "", "ttl=255 sends LCM traffic off this host"},
      {"tcpq://192.0.2.1:7700", "", "sends LCM traffic off this host"},
      {host, "[input]\nmax_speed_m_per_s = 1e300\n", "input.max_speed_m_per_s"},
      {host, "[log]\nmax_lines_per_s = 1e300\n", "log.max_lines_per_s must be in (0, 1000]"},
  };
  const pid_t daemon_pid = daemon_->pid();
  const std::int64_t attacked = MissesOver([&] {
    for (const Attempt& attempt : attempts) {
      // Each file also asks for a new error target: nothing of a refused file may be taken.
      WriteConfig(attempt.lcm_url, "error_target_percent = 3\n", attempt.tables);
      ASSERT_EQ(ExitStatusOf(Spawn([daemon_pid] { return kill(daemon_pid, SIGHUP); })), 0);
      std::this_thread::sleep_for(std::chrono::milliseconds(300));
    }
  });
  ASSERT_TRUE(daemon_->running()) << daemon_->Log();
  EXPECT_LE(attacked, MissBound(quiet)) << "quiet: " << quiet;
  const std::string log = daemon_->Log();
  for (const Attempt& attempt : attempts) {
    EXPECT_NE(log.find(attempt.refusal), std::string::npos) << attempt.refusal << "\n" << log;
  }
  EXPECT_NE(log.find("SIGHUP: config reload refused:"), std::string::npos) << log;
  EXPECT_EQ(monitor_.LastStatus()->error_target_percent, before.error_target_percent);
  // Served on: a driver is admitted and its press is felt.
  ASSERT_NO_FATAL_FAILURE(ExpectADriverIsServed());
  // And a good file is still taken: the refusals were the values', not the reload's.
  WriteConfig(host, "error_target_percent = 3\n");
  daemon_->Signal(SIGHUP);
  EXPECT_TRUE(
      monitor_.WaitForStatus([](const status_t& s) { return s.error_target_percent == 3; }, 3))
      << daemon_->Log();
}

}  // namespace
}  // namespace hapticsim
