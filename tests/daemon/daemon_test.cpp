// The daemon driven directly: a command or a signal in, the supervisor's decision and the status
// message out. Real regions on real threads and a map made by the real sweep; no transport (LCM,
// shared memory and the control socket are off), so nothing here needs a network.
#include "daemon/daemon.hpp"

#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <fstream>
#include <functional>
#include <string>
#include <thread>

#include "core/errormap/error_map.hpp"
#include "core/errormap/error_map_file.hpp"
#include "tests/support/run_command.hpp"

namespace hapticsim {
namespace {

std::string Temp(const std::string& name) { return ::testing::TempDir() + "daemon_test_" + name; }

// A two-configuration map for the default scene, made by the real sweep (a few seconds): the
// primary sizes 1 (cheaper, about 2.7 % error) and 3 (about 0.4 %). Its costs are then set to
// what the sweep measures on a quiet machine (18.3 and 35.6 µs per simulated ms): measured beside
// the suite's other tests, size 3 once came out the cheaper, and the choices below are about the
// supervisor's rules, not the machine's load. One map per process: CTest runs these tests as
// separate processes, two at a time.
const std::string& SmallMap() {
  static const std::string path = [] {
    const std::string suffix = std::to_string(getpid());
    const std::string grid = Temp("grid_" + suffix + ".toml"), map = Temp("map_" + suffix + ".hsmap");
    std::ofstream(grid) << "[axes]\nsecondary_lod = [2]\nprimary_size = [1, 3]\n"
                           "secondary_rate = [1000.0]\nfrequency = [1.0]\n";
    const auto result =
        testing::RunCommand({HAPTICSIM_CLI_PATH, "sweep", "--grid", grid, "--out", map});
    EXPECT_EQ(result.exit_status, 0) << result.err;
    ErrorMap swept = LoadErrorMap(map);
    EXPECT_EQ(swept.samples.size(), 2u);
    for (MapSample& sample : swept.samples) {
      const double size = sample.point[static_cast<int>(MapAxis::kPrimarySize)];
      EXPECT_TRUE(size == 1 || size == 3) << size;
      sample.cost_us_per_ms = size == 1 ? std::array<double, kMapCostRegions>{2.6, 15.7, 0, 0}
                                        : std::array<double, kMapCostRegions>{11.1, 24.5, 0, 0};
    }
    SaveErrorMap(swept, map);
    return map;
  }();
  return path;
}

// The daemon's config file: the map, the target, no transport, a status message every 20 ms.
std::string ConfigFile(const std::string& name, double target_percent) {
  const std::string path = Temp(name + ".toml");
  std::ofstream(path) << "[supervisor]\nerror_map = \"" << SmallMap()
                      << "\"\nerror_target_percent = " << target_percent
                      << "\nstatus_rate_hz = 50\n[lcm]\nenabled = false\n[control]\nenabled = "
                         "false\n[deformation]\nrate_hz = 0\n";
  return path;
}

DaemonArguments ArgumentsFor(const std::string& config_file) {
  DaemonArguments args;
  args.config = config_file;
  return args;
}

// Ticks as Daemon::Run does, until `done` holds (true) or `timeout_s` has passed (false).
bool TickUntil(Daemon& daemon, const std::function<bool()>& done, double timeout_s = 20) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (std::chrono::steady_clock::now() < end) {
    const long next_ns = daemon.Tick(HapticLoop::NowNs());
    if (done()) return true;
    std::this_thread::sleep_for(std::chrono::nanoseconds(next_ns));
  }
  return false;
}

command_t Command(int kind) {
  command_t command{};
  command.command = kind;
  return command;
}

command_t SetTarget(double percent) {
  command_t command = Command(command_t::SET_ERROR_TARGET);
  command.error_target_percent = percent;
  return command;
}

bool StartsWith(const std::string& text, const std::string& prefix) {
  return text.rfind(prefix, 0) == 0;
}

class DaemonTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string config = ConfigFile("config", 7.0);
    daemon_ =
        std::make_unique<Daemon>(ArgumentsFor(config), LoadStartupConfig(ArgumentsFor(config)));
  }
  const ConfigurationSupervisor& supervisor() { return daemon_->supervisor(); }
  // Ticks until the supervisor has nothing left to choose or move.
  bool Settle() {
    return TickUntil(*daemon_, [&] {
      return !supervisor().choosing() && !supervisor().moving() && !supervisor().pending();
    });
  }
  // Ticks until a status message made after now says what `holds` asks.
  bool StatusSays(const std::function<bool(const status_t&)>& holds) {
    const std::int64_t after = HapticLoop::NowNs();
    return TickUntil(*daemon_, [&] {
      return daemon_->last_status().utime > 0 && holds(daemon_->last_status()) &&
             HapticLoop::NowNs() - after > 40'000'000;  // two status periods
    });
  }
  std::unique_ptr<Daemon> daemon_;
};

TEST_F(DaemonTest, StartsWithTheCheapestConfigurationThatMeetsTheTarget) {
  EXPECT_EQ(supervisor().active().primary_size, 1);  // about 2.7 % against 7 %
  EXPECT_TRUE(supervisor().decision().have_map);
  EXPECT_TRUE(supervisor().decision().target_met);
  ASSERT_TRUE(StatusSays([](const status_t& s) { return s.primary_size == 1; }));
  const status_t& status = daemon_->last_status();
  EXPECT_EQ(status.error_target_percent, 7.0);
  EXPECT_TRUE(status.target_met);
  EXPECT_GT(status.error_percent, 0.0);
  EXPECT_LT(status.error_percent, 7.0);
  EXPECT_FALSE(status.pinned);
}

TEST_F(DaemonTest, ATighterTargetSwitchesToTheConfigurationThatMeetsIt) {
  const std::string answer = daemon_->OnCommand(SetTarget(1.0), "a test");
  EXPECT_TRUE(StartsWith(answer, "ok: error target 1.0 %")) << answer;
  EXPECT_EQ(supervisor().target_percent(), 1.0);
  ASSERT_TRUE(Settle());
  EXPECT_EQ(supervisor().active().primary_size, 3);  // about 0.4 % against 1 %
  EXPECT_EQ(supervisor().decision().configuration.primary_size, 3);
  ASSERT_TRUE(StatusSays([](const status_t& s) { return s.primary_size == 3; }));
  EXPECT_EQ(daemon_->last_status().error_target_percent, 1.0);
  EXPECT_TRUE(daemon_->last_status().target_met);
  EXPECT_LT(daemon_->last_status().error_percent, 1.0);
}

TEST_F(DaemonTest, AnUnmeetableTargetKeepsTheLeastErrorAndSaysTheTargetIsMissed) {
  EXPECT_TRUE(StartsWith(daemon_->OnCommand(SetTarget(0.01), "a test"), "ok:"));
  ASSERT_TRUE(Settle());
  EXPECT_EQ(supervisor().active().primary_size, 3);
  EXPECT_FALSE(supervisor().decision().target_met);
  ASSERT_TRUE(StatusSays([](const status_t& s) { return s.error_target_percent == 0.01; }));
  EXPECT_FALSE(daemon_->last_status().target_met);
}

TEST_F(DaemonTest, ACommandOutOfRangeIsRefusedAndChangesNothing) {
  for (const command_t& command : {SetTarget(0), SetTarget(-3), SetTarget(101), Command(99)}) {
    const std::string answer = daemon_->OnCommand(command, "a test");
    EXPECT_TRUE(StartsWith(answer, "refused: ")) << answer;
  }
  command_t pin = Command(command_t::PIN_CONFIGURATION);
  pin.primary_size = 0, pin.secondary_lod = 2, pin.secondary_rate_hz = 1000;
  EXPECT_TRUE(StartsWith(daemon_->OnCommand(pin, "a test"), "refused: "));
  EXPECT_FALSE(supervisor().choosing());
  EXPECT_EQ(supervisor().target_percent(), 7.0);
  EXPECT_EQ(supervisor().active().primary_size, 1);
}

TEST_F(DaemonTest, APinHoldsThroughANewTargetUntilReleased) {
  command_t pin = Command(command_t::PIN_CONFIGURATION);
  pin.primary_size = 3, pin.secondary_lod = 2, pin.secondary_rate_hz = 1000;
  EXPECT_TRUE(StartsWith(daemon_->OnCommand(pin, "a test"), "ok: verifying the pin"));
  ASSERT_TRUE(Settle());
  EXPECT_TRUE(supervisor().pinned());
  EXPECT_EQ(supervisor().active().primary_size, 3);
  // A loose target would choose primary_size 1; the pin holds.
  EXPECT_TRUE(StartsWith(daemon_->OnCommand(SetTarget(50), "a test"), "ok:"));
  ASSERT_TRUE(Settle());
  EXPECT_TRUE(supervisor().pinned());
  EXPECT_EQ(supervisor().active().primary_size, 3);
  ASSERT_TRUE(StatusSays([](const status_t& s) { return s.pinned && s.primary_size == 3; }));

  EXPECT_TRUE(StartsWith(daemon_->OnCommand(Command(command_t::RELEASE_CONFIGURATION), "a test"),
                         "ok: released"));
  ASSERT_TRUE(Settle());
  EXPECT_FALSE(supervisor().pinned());
  EXPECT_EQ(supervisor().active().primary_size, 1);
  ASSERT_TRUE(StatusSays([](const status_t& s) { return !s.pinned && s.primary_size == 1; }));
}

TEST_F(DaemonTest, ResetRestartsTheRegionsWhereTheyAre) {
  const std::int64_t before = daemon_->loop().reconfigurations();
  EXPECT_TRUE(StartsWith(daemon_->OnCommand(Command(command_t::RESET), "a test"), "ok:"));
  EXPECT_EQ(daemon_->loop().reconfigurations(), before + 1);
  EXPECT_EQ(supervisor().active().primary_size, 1);
  ASSERT_TRUE(StatusSays([&](const status_t& s) { return s.reconfigurations == before + 1; }));
}

TEST(DaemonSignals, SighupTakesTheNewTargetARefusedFileKeepsItAndSigtermStops) {
  const std::string config = ConfigFile("reload", 7.0);
  Daemon daemon(ArgumentsFor(config), LoadStartupConfig(ArgumentsFor(config)));
  EXPECT_EQ(daemon.supervisor().active().primary_size, 1);

  std::ofstream(config, std::ios::trunc) << "[supervisor]\nerror_target_percent = nonsense\n";
  EXPECT_TRUE(daemon.OnSignal(SIGHUP));
  EXPECT_EQ(daemon.supervisor().target_percent(), 7.0);  // refused: kept
  EXPECT_EQ(daemon.supervisor().map_path(), SmallMap());

  ConfigFile("reload", 1.0);
  EXPECT_TRUE(daemon.OnSignal(SIGHUP));
  EXPECT_EQ(daemon.supervisor().target_percent(), 1.0);
  ASSERT_TRUE(TickUntil(daemon, [&] { return daemon.supervisor().active().primary_size == 3; }));

  EXPECT_FALSE(daemon.OnSignal(SIGTERM));
  EXPECT_FALSE(daemon.OnSignal(SIGINT));
  daemon.Stop();
  daemon.Stop();  // twice: nothing more
}

}  // namespace
}  // namespace hapticsim
