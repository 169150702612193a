// hapticsimd's parts without a network: LCM encode/decode at the Release flags, the config file,
// the input checks and the deadline bookkeeping. (The lock-free hand-overs are in tests/threads.)
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <tuple>

#include "core/error.hpp"
#include "core/regions/async_regions.hpp"
#include "daemon/command_check.hpp"
#include "daemon/daemon_config.hpp"
#include "daemon/haptic_loop.hpp"
#include "daemon/input_guard.hpp"
#include "daemon/overload_watch.hpp"
#include "daemon/supervisor.hpp"
#include "hapticsim/command_t.hpp"
#include "hapticsim/device_input_t.hpp"
#include "hapticsim/force_feedback_t.hpp"
#include "hapticsim/status_t.hpp"
#include "rt/deadline_monitor.hpp"
#include "tests/support/box_stl.hpp"

namespace hapticsim {
namespace {

template <typename T>
T RoundTrip(const T& message) {
  std::vector<std::uint8_t> buffer(static_cast<size_t>(message.getEncodedSize()));
  EXPECT_EQ(message.encode(buffer.data(), 0, static_cast<int>(buffer.size())),
            static_cast<int>(buffer.size()));
  T back{};
  EXPECT_EQ(back.decode(buffer.data(), 0, static_cast<int>(buffer.size())),
            static_cast<int>(buffer.size()));
  return back;
}

// The LCM notes: g++ 12 at -O2/-O3 can decode doubles as 0 unless -fno-strict-aliasing.
TEST(LcmTypes, EveryTypeSurvivesEncodeAndDecodeWithItsFloatingPointValues) {
  device_input_t input{};
  input.utime = 123456789, input.seq = 42;
  input.position[0] = 0.125, input.position[1] = -1.5e-3, input.position[2] = 0.0101;
  const device_input_t input_back = RoundTrip(input);
  EXPECT_EQ(input_back.seq, 42);
  for (int c = 0; c < 3; ++c) EXPECT_EQ(input_back.position[c], input.position[c]);

  force_feedback_t force{};
  force.seq = 7, force.force[2] = -1.486, force.error_percent = 2.5, force.flags = 5;
  const force_feedback_t force_back = RoundTrip(force);
  EXPECT_EQ(force_back.force[2], -1.486);
  EXPECT_EQ(force_back.error_percent, 2.5);
  EXPECT_EQ(force_back.flags, 5);

  status_t status{};
  status.secondary_rate_hz = 600, status.spectral_radius = 0.9895, status.error_map = "m.hsmap";
  status.num_regions = 2;
  status.regions.resize(2);
  status.regions[1].name = "secondary";
  status.regions[1].execution_p99_us = 213.5;
  const status_t status_back = RoundTrip(status);
  EXPECT_EQ(status_back.spectral_radius, 0.9895);
  EXPECT_EQ(status_back.regions[1].name, "secondary");
  EXPECT_EQ(status_back.regions[1].execution_p99_us, 213.5);

  command_t command{};
  command.command = command_t::SET_ERROR_TARGET, command.error_target_percent = 3.25;
  EXPECT_EQ(RoundTrip(command).error_target_percent, 3.25);
}

TEST(LcmTypes, TheDaemonsForceFlagsAreTheMessageConstants) {
  EXPECT_EQ(force_flags::kInContact, force_feedback_t::FLAG_IN_CONTACT);
  EXPECT_EQ(force_flags::kErrorTargetExceeded, force_feedback_t::FLAG_ERROR_TARGET_EXCEEDED);
  EXPECT_EQ(force_flags::kLookupClamped, force_feedback_t::FLAG_LOOKUP_CLAMPED);
  EXPECT_EQ(force_flags::kInputStale, force_feedback_t::FLAG_INPUT_STALE);
  EXPECT_EQ(force_flags::kReconfiguring, force_feedback_t::FLAG_RECONFIGURING);
  EXPECT_EQ(force_flags::kNoErrorMap, force_feedback_t::FLAG_NO_ERROR_MAP);
  EXPECT_EQ(force_flags::kInputRejected, force_feedback_t::FLAG_INPUT_REJECTED);
  EXPECT_EQ(force_flags::kBoundaryStale, force_feedback_t::FLAG_BOUNDARY_STALE);
  EXPECT_EQ(force_flags::kForceLimited, force_feedback_t::FLAG_FORCE_LIMITED);
  EXPECT_EQ(force_flags::kPortDissipating, force_feedback_t::FLAG_PORT_DISSIPATING);
  EXPECT_EQ(force_flags::kFaultLatched, force_feedback_t::FLAG_FAULT_LATCHED);
}

// A config file of this test's own: CTest runs the tests of this binary in parallel, and two
// writing one file made each other's errors.
std::string ConfigTestPath() {
  return ::testing::TempDir() + "hapticsimd_config_" +
         ::testing::UnitTest::GetInstance()->current_test_info()->name() + ".toml";
}

std::string ConfigError(const std::string& text) {
  const std::string path = ConfigTestPath();
  std::ofstream(path) << text;
  try {
    LoadDaemonConfig(path);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(DaemonConfig, DefaultsAreValidHostLocalAndRoundTrip) {
  const DaemonConfig defaults = DefaultDaemonConfig();
  EXPECT_NO_THROW(ValidateDaemonConfig(defaults));
  EXPECT_NE(defaults.lcm_url.find("ttl=0"), std::string::npos);
  const std::string path = ::testing::TempDir() + "hapticsimd_config_roundtrip.toml";
  std::ofstream(path) << FormatDaemonConfig(defaults);
  const DaemonConfig back = LoadDaemonConfig(path);
  EXPECT_EQ(FormatDaemonConfig(back), FormatDaemonConfig(defaults));
  // The device input is left unset, so a config made from the defaults (the installed one) gives
  // the input to shared memory once [shm] is enabled in it, as the defaults themselves do.
  EXPECT_EQ(back.device_input, "");
  std::string text = FormatDaemonConfig(defaults);
  const std::string shm_off = "[shm]\nenabled = false";
  ASSERT_NE(text.find(shm_off), std::string::npos) << text;
  text.replace(text.find(shm_off), shm_off.size(), "[shm]\nenabled = true");
  std::ofstream(path) << text;
  EXPECT_EQ(DeviceInputOf(LoadDaemonConfig(path)), "shm");
}

TEST(DaemonConfig, MistakesAreRefusedNamingTheKeyAndLine) {
  EXPECT_NE(ConfigError("[supervisor]\nerror_target = 5\n")
                .find(":2: unknown key supervisor.error_target"),
            std::string::npos)
      << ConfigError("[supervisor]\nerror_target = 5\n");
  EXPECT_NE(ConfigError("[supervisor]\nerror_target_percent = 0\n")
                .find("supervisor.error_target_percent must be in (0, 100]"),
            std::string::npos);
  EXPECT_NE(ConfigError("[input]\nstale_after_s = \"soon\"\n")
                .find("input.stale_after_s must be a number"),
            std::string::npos);
  EXPECT_NE(ConfigError("[realtime]\nfifo_priority = 120\n").find("realtime.fifo_priority"),
            std::string::npos);
  for (const char* rate : {"-1", "0.5", "1000", "nan", "\"fast\""}) {
    const std::string text = std::string("[deformation]\nrate_hz = ") + rate + "\n";
    EXPECT_NE(ConfigError(text).find("deformation.rate_hz must be"), std::string::npos)
        << ConfigError(text);
  }
  EXPECT_NE(ConfigError("[lcm]\ndeformation_channel = \"\"\n")
                .find("lcm.deformation_channel must be a channel name"),
            std::string::npos);
  EXPECT_NE(ConfigError("[realtime]\nsleep_at_rest = 3\n")
                .find("realtime.sleep_at_rest must be true or false"),
            std::string::npos)
      << ConfigError("[realtime]\nsleep_at_rest = 3\n");
  // Whole numbers as written: no float cast (1e103 does not fit an int64: found by fuzzing), no
  // wrapping round into range.
  for (const char* priority : {"4.4e103", "10.0"}) {
    const std::string text = std::string("[realtime]\nfifo_priority = ") + priority + "\n";
    EXPECT_NE(ConfigError(text).find("realtime.fifo_priority must be a whole number"),
              std::string::npos)
        << ConfigError(text);
  }
  EXPECT_NE(ConfigError("[realtime]\nfifo_priority = 4294967306\n")
                .find("realtime.fifo_priority must be from 0 (off) to 99"),
            std::string::npos)
      << ConfigError("[realtime]\nfifo_priority = 4294967306\n");
  EXPECT_NE(ConfigError("[realtime]\ncpus = [4294967297]\n").find("realtime.cpus"),
            std::string::npos);
  // Every number has a ceiling: at it accepted, beyond it refused naming the key.
  const std::pair<const char*, const char*> ceilings[] = {
      {"[input]\nmax_speed_m_per_s = 100\n", ""},
      {"[input]\nmax_speed_m_per_s = 1e300\n", "input.max_speed_m_per_s must be in (0, 100]"},
      {"[input]\nworkspace_margin_m = 10\n", ""},
      {"[input]\nworkspace_margin_m = 11\n", "input.workspace_margin_m must be from 0 to 10"},
      {"[log]\nmax_lines_per_s = 1000\n", ""},
      {"[log]\nmax_lines_per_s = 1e9\n", "log.max_lines_per_s must be in (0, 1000]"},
      {"[device]\nmax_force_n = 100\nengage_rate_n_per_ms = 0.1\nfault_force_n = 100\n", ""},
      {"[device]\nmax_force_n = 1e300\n", "device.max_force_n must be in (0, 100] N"},
      // A slew below the lift-off's default 0.1 N per ms loads as before the key came.
      {"[device]\nmax_force_n = 3\nmax_force_rate_n_per_ms = 0.05\nengage_rate_n_per_ms = 0.03\n",
       ""},
      {"[device]\nlift_off_rate_n_per_ms = 100\n", ""},
      // The service socket: an absolute path a Unix socket can have (107 bytes).
      {"[shm]\nsocket = \"/run/hapticsim/hapticsimd.sock\"\n", ""},
      {"[shm]\nsocket = \"hapticsimd.sock\"\n", "shm.socket must be an absolute path"},
      {"[shm]\nsocket = \"/run/hapticsim/\"\n", "shm.socket must be an absolute path"},
  };
  for (const auto& [text, message] : ceilings) {
    const std::string error = ConfigError(text);
    if (*message == 0) {
      EXPECT_EQ(error, "") << text;
    } else {
      EXPECT_NE(error.find(message), std::string::npos) << text << error;
    }
  }
  const std::string longest = "/" + std::string(106, 's'), too_long = longest + "s";
  EXPECT_EQ(ConfigError("[shm]\nsocket = \"" + longest + "\"\n"), "");
  EXPECT_NE(ConfigError("[shm]\nsocket = \"" + too_long + "\"\n").find("at most 107 bytes"),
            std::string::npos);
  // The segment's name is gone (a named segment could be opened, squatted and truncated by
  // anyone who could see it): the key says what replaced it.
  EXPECT_NE(ConfigError("[shm]\nname = \"/hapticsim\"\n")
                .find("shm.name is gone: the segment has no name any more"),
            std::string::npos)
      << ConfigError("[shm]\nname = \"/hapticsim\"\n");
  EXPECT_NE(ConfigError("[lcm\nurl = 3\n").find(ConfigTestPath() + ":1"), std::string::npos)
      << ConfigError("[lcm\nurl = 3\n");
}

// What the scene's adaptivity does in the daemon: the supervisor chooses primary_size,
// secondary_lod and secondary_rate; everything else — here two shells with the outer one at
// adaptivity.outer_rate — stays the scene's, in the regions the daemon builds (SceneWith, as
// main.cpp builds its HapticLoop). Without [adaptivity] the daemon starts from the default size
// at equal rates.
// hapticsimd's config check takes an object from a geometry file: here a box drawn as an STL,
// 4 × 4 × 4 voxels of 1 cm, with a [[material]] table and its back face held by a [[support]]
// plane. (Objects that leave voxels of their lattice empty are served too: voxel_object_test.cpp;
// a daemon serving a block: HapticsimdDeformation.ABlockFromAFileIsServedOnItsOwnLattice.)
TEST(DaemonConfig, AGeometryFromAFilePassesTheCheckAndOneWithoutSupportsIsRefused) {
  const std::string stl = ConfigTestPath() + ".box.stl";
  testing::WriteBoxStl(stl, 0.04);
  const std::string scene = ConfigTestPath() + ".scene.toml";
  const std::string object = "[geometry]\nfile = \"" + stl +
                             "\"\nspacing_m = 0.01\n"
                             "[[material]]\nlabel = 1\nyoungs_modulus = 20000.0\n";
  std::ofstream(scene) << object << "[[support]]\nplane_point = [0.0, 0.0, 0.04]\n"
                       << "plane_normal = [0.0, 0.0, 1.0]\n";
  EXPECT_EQ(ConfigError("[scene]\nfile = \"" + scene + "\"\n"), "");
  // Without supports the object floats: refused, saying what to add.
  std::ofstream(scene) << object;
  const std::string error = ConfigError("[scene]\nfile = \"" + scene + "\"\n");
  EXPECT_NE(error.find("needs [[support]] tables"), std::string::npos) << error;
}

// A sliding tool is served (contact.model = "proxy", or a stroke's scene); its primary must reach
// the tip's nodes with a node to spare for the time a follow takes, and a scene whose primary
// cannot is refused saying what to set.
TEST(DaemonConfig, ASlidingToolIsServedAndAPrimaryTooSmallForItIsRefused) {
  const std::string scene = ConfigTestPath() + ".proxy.toml";
  std::ofstream(scene) << "[contact]\nmodel = \"proxy\"\n[adaptivity]\nprimary_size = 3\n";
  const std::string path = ConfigTestPath();
  std::ofstream(path) << "[scene]\nfile = \"" << scene << "\"\n";
  EXPECT_EQ(LoadDaemonConfig(path).scene.contact.model, ContactModel::kProxy);
  std::ofstream(scene) << "[input]\nwaveform = \"stroke\"\n[adaptivity]\nprimary_size = 3\n";
  EXPECT_EQ(ConfigError("[scene]\nfile = \"" + scene + "\"\n"), "");
  std::ofstream(scene) << "[contact]\nmodel = \"proxy\"\n[adaptivity]\nprimary_size = 1\n";
  const std::string error = ConfigError("[scene]\nfile = \"" + scene + "\"\n");
  EXPECT_NE(error.find("adaptivity.primary_size >= 2"), std::string::npos) << error;
  // On threads a follow takes time while the tool slides on: a node more than offline, where a
  // primary of 2 strokes (RegionStroke.ThePrimaryMustReachTwoNodesFromTheProxy).
  std::ofstream(scene) << "[contact]\nmodel = \"proxy\"\n[adaptivity]\nprimary_size = 2\n";
  const std::string threads = ConfigError("[scene]\nfile = \"" + scene + "\"\n");
  EXPECT_NE(threads.find("adaptivity.primary_size >= 3"), std::string::npos) << threads;
  EXPECT_NE(threads.find("on real threads"), std::string::npos) << threads;
}

TEST(DaemonConfig, TheSupervisorChoosesThreeSettingsAndTheSceneKeepsTheRest) {
  const std::string scene_path = ::testing::TempDir() + "hapticsimd_outer_rate_scene.toml";
  std::ofstream(scene_path) << "[adaptivity]\nprimary_size = 2\nsecondary_lod = 2\n"
                               "secondary_rate = 800\nsecondary_regions = 2\nouter_rate = 500\n";
  const std::string path = ConfigTestPath();
  std::ofstream(path) << "[scene]\nfile = \"" << scene_path << "\"\n";
  const DaemonConfig config = LoadDaemonConfig(path);
  EXPECT_EQ(config.scene.adaptivity.outer_rate_hz, 500);
  const SupervisorDecision decision = ChooseConfiguration(config.scene, nullptr, 7.0, std::nullopt);
  EXPECT_EQ(decision.configuration, (RegionConfiguration{2, 2, 800}));
  const AsyncRegions regions(SceneWith(config.scene, decision.configuration));
  ASSERT_EQ(regions.num_regions(), 3);
  EXPECT_EQ(regions.schedule(1).rate_hz, 800);
  EXPECT_EQ(regions.schedule(2).rate_hz, 500);

  const DaemonConfig defaults = DefaultDaemonConfig();
  EXPECT_EQ(defaults.scene.adaptivity.primary_size, RegionConfiguration::kDaemonPrimarySize);
  EXPECT_EQ(defaults.scene.adaptivity.secondary_lod, AdaptivitySettings{}.secondary_lod);
  EXPECT_EQ(defaults.scene.adaptivity.secondary_rate_hz, PrimaryRateHz(defaults.scene));
  EXPECT_EQ(RegionConfiguration{}.secondary_rate_hz, AdaptivitySettings{}.secondary_rate_hz);
}

// LCM traffic stays on this host unless the config says, in a key of its own, that it may leave:
// ttl=255 and a TCP provider to another machine were accepted as any URL with "://".
TEST(DaemonConfig, AnLcmUrlThatLeavesTheHostNeedsAllowNetwork) {
  for (const char* url : {"udpm://239.255.76.67:7667?ttl=0", "udpm://239.255.76.68:7700?ttl=0",
                          "udpm://239.255.76.67:7667?recv_buf_size=2097152&ttl=0", "memq://",
                          "udpm://239.255.76.67:7667", "tcpq://127.0.0.1:7700",
                          "tcpq://127.1.2.3:7700", "tcpq://localhost:7700"}) {
    EXPECT_EQ(ConfigError(std::string("[lcm]\nurl = \"") + url + "\"\n"), "") << url;
  }
  const std::pair<const char*, const char*> refused[] = {
      {"udpm://239.255.76.67:7667?ttl=1", "lcm.url: ttl=1 sends LCM traffic off this host"},
      {"udpm://239.255.76.67:7667?ttl=255", "lcm.url: ttl=255 sends LCM traffic off this host"},
      {"tcpq://127.evil.example:7700", "lcm.url: tcpq://127.evil.example:7700 sends LCM traffic"},
      {"udpm://239.255.76.67:7667?ttl=256", "lcm.url: ttl must be a whole number from 0 to 255"},
      {"udpm://239.255.76.67:7667?ttl=zero", "lcm.url: ttl must be a whole number from 0 to 255"},
      {"tcpq://10.0.0.5:7700", "lcm.url: tcpq://10.0.0.5:7700 sends LCM traffic off this host"},
      {"carrier-pigeon://home", "lcm.url: unknown LCM provider 'carrier-pigeon'"},
      {"239.255.76.67", "lcm.url must look like udpm://239.255.76.67:7667?ttl=0 or memq://"},
  };
  for (const auto& [url, message] : refused) {
    const std::string error = ConfigError(std::string("[lcm]\nurl = \"") + url + "\"\n");
    EXPECT_NE(error.find(message), std::string::npos) << url << ": " << error;
    if (std::string(message).find("off this host") != std::string::npos) {
      EXPECT_NE(error.find("lcm.allow_network = true"), std::string::npos) << error;
      // Said in so many words, it is allowed.
      EXPECT_EQ(ConfigError(std::string("[lcm]\nallow_network = true\nurl = \"") + url + "\"\n"),
                "")
          << url;
    }
  }
  EXPECT_FALSE(DefaultDaemonConfig().lcm_allow_network);
  EXPECT_FALSE(LcmUrlLeavesHost(DefaultDaemonConfig().lcm_url));
  EXPECT_TRUE(LcmUrlLeavesHost("udpm://239.255.76.67:7667?ttl=1"));
}

// Commands on LCM come from anyone on the bus: taken only when signed, so switching them on
// without a key is refused, naming the key and how to make one.
TEST(DaemonConfig, LcmCommandsNeedAKeyFile) {
  const std::string error = ConfigError("[lcm]\naccept_commands = true\n");
  EXPECT_NE(error.find("lcm.accept_commands = true needs lcm.command_key_file"), std::string::npos)
      << error;
  EXPECT_NE(error.find("hapticsim ctl --make-key FILE"), std::string::npos) << error;
  EXPECT_NE(ConfigError("[lcm]\ncommand_key_file = \"relative.key\"\n").find("absolute path"),
            std::string::npos);
  EXPECT_EQ(ConfigError("[lcm]\naccept_commands = true\ncommand_key_file = \"/etc/k\"\n"), "");
  EXPECT_EQ(ConfigError("[lcm]\nenabled = false\naccept_commands = true\n"), "")
      << "no bus, nothing to take";
}

TEST(DaemonConfig, TheDeviceProfileIsReadCheckedAndOwnsTheInput) {
  const std::string path = ::testing::TempDir() + "hapticsimd_config_device.toml";
  std::ofstream(path) << "[shm]\nenabled = true\n[device]\nmax_force_n = 3.0\n"
                         "max_force_rate_n_per_ms = 0.2\nengage_rate_n_per_ms = 0.03\n"
                         "lift_off_rate_n_per_ms = 0.08\n"
                         "fault_force_n = 20.0\nwatchdog_s = 0.05\npassivity = false\n";
  const DaemonConfig config = LoadDaemonConfig(path);
  EXPECT_EQ(config.port.max_force_n, 3.0);
  EXPECT_EQ(config.port.max_force_rate_n_per_ms, 0.2);
  EXPECT_EQ(config.port.engage_rate_n_per_ms, 0.03);
  EXPECT_EQ(config.port.lift_off_rate_n_per_ms, 0.08);
  EXPECT_EQ(config.port.fault_force_n, 20.0);
  EXPECT_EQ(config.port.watchdog_s, 0.05);
  EXPECT_FALSE(config.port.passivity);
  EXPECT_EQ(DeviceInputOf(config), "shm");  // shared memory enabled: it owns the input
  std::ofstream(path) << FormatDaemonConfig(config);
  EXPECT_EQ(FormatDaemonConfig(LoadDaemonConfig(path)), FormatDaemonConfig(config));
  // A desktop device by default, the input LCM's.
  EXPECT_EQ(DefaultDaemonConfig().port.max_force_n, 8.0);
  EXPECT_EQ(DeviceInputOf(DefaultDaemonConfig()), "lcm");
  const std::pair<const char*, const char*> refused[] = {
      {"[input]\nmax_force_n = 50.0\n", "input.max_force_n moved to [device] max_force_n"},
      {"[device]\nmax_force_n = 1e300\n", "device.max_force_n must be in (0, 100] N"},
      {"[device]\nmax_force_n = 10.0\nfault_force_n = 9.0\n",
       "device.fault_force_n must be from device.max_force_n"},
      {"[device]\nengage_rate_n_per_ms = 1.0\n", "to device.max_force_rate_n_per_ms (0.5)"},
      {"[device]\nwatchdog_s = 0.0\n", "device.watchdog_s must be from 0.05 to 10 s"},
      {"[device]\nengage_rate_n_per_ms = 1e-9\n", "device.engage_rate_n_per_ms must be from"},
      {"[device]\nlift_off_rate_n_per_ms = 101\n", "device.lift_off_rate_n_per_ms must be from"},
      {"[device]\nlift_off_rate_n_per_ms = nan\n", "device.lift_off_rate_n_per_ms must be from"},
      {"[device]\ninput = \"usb\"\n", "device.input must be \"lcm\" or \"shm\" (it is \"usb\")"},
      {"[device]\ninput = \"shm\"\n", "device.input = \"shm\" needs shm.enabled = true"},
      {"[lcm]\nenabled = false\n[device]\ninput = \"lcm\"\n",
       "device.input = \"lcm\" needs lcm.enabled = true"},
  };
  for (const auto& [text, message] : refused) {
    EXPECT_NE(ConfigError(text).find(message), std::string::npos) << text << ConfigError(text);
  }
}

TEST(InputGuard, RejectsEachKindOfBadInputAndAcceptsAHand) {
  InputGuard guard({0.25, 0.25, 0.25}, 0.1, 5.0);  // the default cube's box
  const std::int64_t ms = 1'000'000;
  EXPECT_EQ(guard.Check(1, {0.125, 0.125, 0.0}, 0), InputRejection::kAccepted);
  EXPECT_EQ(guard.Check(2, {0.125, 0.125, 0.001}, ms), InputRejection::kAccepted);  // 1 m/s
  EXPECT_EQ(guard.Check(3, {NAN, 0.125, 0.0}, 2 * ms), InputRejection::kNonFinite);
  EXPECT_EQ(guard.Check(3, {0.125, 0.125, INFINITY}, 2 * ms), InputRejection::kNonFinite);
  EXPECT_EQ(guard.Check(3, {0.125, 0.125, 0.5}, 2 * ms), InputRejection::kOutsideWorkspace);
  EXPECT_EQ(guard.Check(3, {0.125, 0.145, 0.001}, 2 * ms), InputRejection::kJump);  // 20 m/s
  EXPECT_EQ(guard.Check(2, {0.125, 0.125, 0.001}, 2 * ms), InputRejection::kOldSequence);
  EXPECT_EQ(guard.Check(5, {0.125, 0.125, 0.002}, 3 * ms), InputRejection::kAccepted);
  EXPECT_EQ(guard.sequence_gaps(), 1);
  // After a pause the same jump is a plausible move.
  EXPECT_EQ(guard.Check(6, {0.125, 0.145, 0.002}, 1000 * ms), InputRejection::kAccepted);
  // A driver restarted after more than half a second of silence counts from 1 again: a new
  // session, accepted; within the half second the old seq is still refused.
  EXPECT_EQ(guard.Check(1, {0.125, 0.145, 0.002}, 1400 * ms), InputRejection::kOldSequence);
  EXPECT_EQ(guard.Check(1, {0.2, 0.1, -0.01}, 1501 * ms), InputRejection::kAccepted);
  EXPECT_EQ(guard.Check(2, {0.2, 0.1, -0.01}, 1502 * ms), InputRejection::kAccepted);
  // seq from 0 to 2⁵³ (a double holds every one of them: 285,000 years at 1 kHz), at the edges
  // and beyond.
  EXPECT_EQ(guard.Check(-1, {0.2, 0.1, -0.01}, 3000 * ms), InputRejection::kSeqOutOfRange);
  EXPECT_EQ(guard.Check(0, {0.2, 0.1, -0.01}, 3001 * ms), InputRejection::kAccepted);
  EXPECT_EQ(guard.Check(InputGuard::kMaxSeq, {0.2, 0.1, -0.01}, 3002 * ms),
            InputRejection::kAccepted);
  EXPECT_EQ(guard.Check(InputGuard::kMaxSeq + 1, {0.2, 0.1, -0.01}, 4000 * ms),
            InputRejection::kSeqOutOfRange);
  EXPECT_EQ(guard.Check(std::numeric_limits<std::int64_t>::max(), {0.2, 0.1, -0.01}, 5000 * ms),
            InputRejection::kSeqOutOfRange);
  EXPECT_EQ(InputRejectionName(InputRejection::kSeqOutOfRange),
            "seq outside 0 to 2^53 (input.seq counts device periods)");
}

TEST(CommandRateLimit, TakesABurstThenTenASecondAndCountsTheRest) {
  CommandRateLimit limit;
  const std::int64_t ms = 1'000'000;
  for (int i = 0; i < 10; ++i) EXPECT_TRUE(limit.Admit(0)) << i;
  EXPECT_FALSE(limit.Admit(0));
  EXPECT_FALSE(limit.Admit(50 * ms));  // half a token
  EXPECT_TRUE(limit.Admit(100 * ms));
  EXPECT_EQ(limit.refused(), 2);
  // A pin at 1 kHz for 10 s: 100 taken (one every 100 ms), the rest refused.
  CommandRateLimit flood;
  int taken = 0;
  for (std::int64_t k = 0; k < 10'000; ++k) taken += flood.Admit(k * ms);
  EXPECT_LE(taken, 10 + 100);
  EXPECT_GE(taken, 100);
  EXPECT_EQ(flood.refused(), 10'000 - taken);
  // A clock that goes back takes nothing extra.
  CommandRateLimit back;
  for (int i = 0; i < 10; ++i) back.Admit(1000 * ms);
  EXPECT_FALSE(back.Admit(0));
}

TEST(DeadlineMonitor, CountsMissesAndReportsExecutionPercentiles) {
  DeadlineMonitor monitor(1e-3);
  std::int64_t t = 0;
  for (int i = 0; i < 1000; ++i, t += 1'000'000) {
    const std::int64_t execution = i < 980 ? 20'000 : 400'000;  // 20 µs, 2 % at 400 µs
    monitor.Record(t, t + 5'000, t + 5'000 + execution);
  }
  monitor.Record(t, t + 1'500'000, t + 1'520'000);  // woke 1.5 ms late: a miss
  const DeadlineSnapshot s = monitor.TakeSnapshot();
  EXPECT_EQ(s.cycles, 1001);
  EXPECT_EQ(s.misses, 1);
  EXPECT_NEAR(s.worst_lateness_s, 1.5e-3, 1e-9);
  // Each percentile is the upper edge of its 25 %-wide bin: at most a bin above the value.
  EXPECT_GE(s.recent_execution_p50_s, 20e-6);
  EXPECT_LE(s.recent_execution_p50_s, 20e-6 * 1.25);
  // 981 of the 1001 steps took 20 µs: the 99th percentile (the 991st) is one of the 400 µs ones.
  EXPECT_GE(s.recent_execution_p99_s, 400e-6);
  EXPECT_LE(s.recent_execution_p99_s, 400e-6 * 1.25);
  EXPECT_NEAR(s.recent_execution_max_s, 400e-6, 1e-9);
  DeadlineEvent event;
  ASSERT_TRUE(monitor.PopEvent(&event));
  EXPECT_EQ(event.lateness_ns, 1'500'000);
  EXPECT_FALSE(monitor.PopEvent(&event));
  EXPECT_EQ(monitor.TakeSnapshot().recent_cycles, 0);  // the window restarts
}

// A map with two configurations of a 9³ cube whose errors and costs the test sets: the choice
// must follow the stability-first rules, with the configuration's fields in the right places.
ErrorMap TwoConfigurationMap(const Scene& scene) {
  std::array<std::vector<double>, kNumMapAxes> axes;
  const MapPoint at = PointOfScene(scene);
  for (int a = 0; a < kNumMapAxes; ++a) axes[a] = {at[a]};
  axes[static_cast<int>(MapAxis::kSecondaryLod)] = {2};
  axes[static_cast<int>(MapAxis::kPrimarySize)] = {1, 3};
  axes[static_cast<int>(MapAxis::kSecondaryRate)] = {1000};
  ErrorMap map = ErrorMap::MakeGrid(axes);
  map.samples[0].status = map.samples[1].status = SampleStatus::kOk;
  map.samples[0].max_magnitude_percent = 5.0;  // size 1: cheap, less accurate
  map.samples[0].cost_us_per_ms = {10, 10, 0, 0};
  map.samples[1].max_magnitude_percent = 1.0;  // size 3: dearer, more accurate
  map.samples[1].cost_us_per_ms = {20, 10, 0, 0};
  return map;
}

TEST(Supervisor, ChoosesTheCheapestConfigurationMeetingTheTargetElseTheMostAccurate) {
  Scene scene;
  scene.mesh.nodes = 9;
  ErrorMap map = TwoConfigurationMap(scene);
  const SupervisorDecision loose = ChooseConfiguration(scene, &map, 7.0, std::nullopt);
  EXPECT_EQ(loose.configuration.primary_size, 1);
  EXPECT_EQ(loose.configuration.secondary_lod, 2);
  EXPECT_EQ(loose.configuration.secondary_rate_hz, 1000);
  EXPECT_TRUE(loose.target_met);
  EXPECT_DOUBLE_EQ(loose.error_percent, 5.0);

  const SupervisorDecision tight = ChooseConfiguration(scene, &map, 2.0, std::nullopt);
  EXPECT_EQ(tight.configuration.primary_size, 3);
  EXPECT_TRUE(tight.target_met);

  const SupervisorDecision impossible = ChooseConfiguration(scene, &map, 0.1, std::nullopt);
  EXPECT_EQ(impossible.configuration.primary_size, 3);  // the most accurate one
  EXPECT_FALSE(impossible.target_met);
  // Deadlines before accuracy: below size 3's cost only size 1 is left, and below size 1's none.
  const SupervisorDecision cheaper =
      ChooseConfiguration(scene, &map, 2.0, std::nullopt, tight.cost_us_per_ms);
  EXPECT_EQ(cheaper.configuration.primary_size, 1);
  EXPECT_FALSE(cheaper.target_met);
  EXPECT_THROW(ChooseConfiguration(scene, &map, 2.0, std::nullopt, cheaper.cost_us_per_ms), Error);

  map.samples[1].status = SampleStatus::kPredictedUnstable;  // never chosen, whatever its error
  const SupervisorDecision safe = ChooseConfiguration(scene, &map, 2.0, std::nullopt);
  EXPECT_EQ(safe.configuration.primary_size, 1);
  EXPECT_FALSE(safe.target_met);

  scene.adaptivity.primary_size = 3;  // without a map: the scene's own configuration
  const SupervisorDecision no_map = ChooseConfiguration(scene, nullptr, 7.0, std::nullopt);
  EXPECT_EQ(no_map.configuration.primary_size, 3);
  EXPECT_FALSE(no_map.have_map);
  EXPECT_EQ(no_map.error_percent, -1);
}

// Stable by construction (docs/regions.md): no configuration whose regions meet their own limits
// is refused. ν 0.49, k 1, r 2 at 700 Hz: the bare exchange grows by 1.47 per common period (the
// spectral estimate the supervisor used to run refused it); the interface controllers hold it.
// Only regions that cannot be built are refused, with the reason.
TEST(Supervisor, RunsWhatTheBareExchangeCannotHoldAndRefusesOnlyRegionsThatCannotBeBuilt) {
  Scene scene;
  scene.material.poisson_ratio = 0.49;
  const RegionConfiguration grows{2, 1, 700};
  const SupervisorDecision pinned = ChooseConfiguration(scene, nullptr, 7.0, grows);
  EXPECT_EQ(pinned.configuration, grows);
  const SupervisorDecision own = ChooseConfiguration(SceneWith(scene, grows), nullptr, 7.0, {});
  EXPECT_EQ(own.configuration, grows) << "no fallback to equal rates";
  EXPECT_EQ(VerifyCentredOn(scene, grows, {2, 3, 0}).configuration, grows);

  scene.adaptivity.secondary_regions = 4;  // primary_size 2 leaves the fourth shell empty
  scene.adaptivity.shell_cells = 2;
  try {
    (void)ChooseConfiguration(scene, nullptr, 7.0, RegionConfiguration{2, 2, 600});
    ADD_FAILURE() << "regions that cannot be built were chosen";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("cannot run on this scene"), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("secondary region 4"), std::string::npos) << e.what();
  }
}

// What the daemon will not trust in a map, each with the key it names: an axis longer than the
// lookup takes (the daemon exited: ChooseConfiguration threw), a configuration value no scene
// accepts (cast from a double to int: undefined behaviour for 1e300). The choice then runs as
// with no map.
TEST(Supervisor, AMapTheDaemonCannotUseIsNamedAndChosenAsNoMap) {
  Scene scene;
  scene.mesh.nodes = 9;
  const ErrorMap good = TwoConfigurationMap(scene);
  scene.adaptivity.primary_size = 3;  // what runs without a map
  EXPECT_EQ(MapProblem(scene, good), "");

  std::array<std::vector<double>, kNumMapAxes> axes = good.axes;
  axes[static_cast<int>(MapAxis::kPrimarySize)].clear();
  for (int size = 1; size <= 65; ++size) {
    axes[static_cast<int>(MapAxis::kPrimarySize)].push_back(size);
  }
  ErrorMap long_axis = ErrorMap::MakeGrid(axes);
  for (MapSample& sample : long_axis.samples) sample.status = SampleStatus::kOk;
  EXPECT_NE(
      MapProblem(scene, long_axis).find("adaptivity.primary_size: a lookup axis needs 1 to 64"),
      std::string::npos)
      << MapProblem(scene, long_axis);
  const SupervisorDecision no_map = ChooseConfiguration(scene, &long_axis, 7.0, std::nullopt);
  EXPECT_FALSE(no_map.have_map);

  for (const double size : {1e300, 2.5, -1.0, 1001.0}) {
    ErrorMap bad = good;
    bad.axes[static_cast<int>(MapAxis::kPrimarySize)] = {1, size};
    if (size < 1) bad.axes[static_cast<int>(MapAxis::kPrimarySize)] = {size, 1};
    EXPECT_NE(MapProblem(scene, bad).find("adaptivity.primary_size"), std::string::npos)
        << size << ": " << MapProblem(scene, bad);
    EXPECT_FALSE(ChooseConfiguration(scene, &bad, 7.0, std::nullopt).have_map) << size;
  }
  ErrorMap bad_rate = good;
  bad_rate.axes[static_cast<int>(MapAxis::kSecondaryRate)] = {1e308};
  EXPECT_NE(MapProblem(scene, bad_rate).find("adaptivity.secondary_rate"), std::string::npos)
      << MapProblem(scene, bad_rate);
}

// Where the tool moves the regions, the status's error is looked up for that node: between the
// mapped contact nodes interpolated, beyond them the edge's and flagged, and none where the map
// calls the configuration unstable.
TEST(Supervisor, TheErrorFollowsTheContactNodeBetweenMappedNodesAndIsFlaggedBeyondThem) {
  Scene scene;
  scene.mesh.nodes = 9;  // middle of the front face: (4, 4, 0)
  std::array<std::vector<double>, kNumMapAxes> axes;
  const MapPoint at = PointOfScene(scene);
  for (int a = 0; a < kNumMapAxes; ++a) axes[a] = {at[a]};
  axes[static_cast<int>(MapAxis::kSecondaryLod)] = {2};
  axes[static_cast<int>(MapAxis::kPrimarySize)] = {1};
  axes[static_cast<int>(MapAxis::kSecondaryRate)] = {1000};
  axes[static_cast<int>(MapAxis::kContactNodeX)] = {2, 4};
  ErrorMap map = ErrorMap::MakeGrid(axes);
  ASSERT_EQ(map.samples.size(), 2u);
  map.samples[0].status = map.samples[1].status = SampleStatus::kOk;
  map.samples[0].max_magnitude_percent = 3.0;  // node x = 2
  map.samples[1].max_magnitude_percent = 1.0;  // node x = 4
  const RegionConfiguration c{1, 2, 1000};

  NodeError e = LookupErrorAt(map, scene, c, {4, 4, 0});
  EXPECT_TRUE(e.usable);
  EXPECT_DOUBLE_EQ(e.error_percent, 1.0);
  EXPECT_FALSE(e.clamped);
  e = LookupErrorAt(map, scene, c, {3, 4, 0});  // between the mapped nodes
  EXPECT_DOUBLE_EQ(e.error_percent, 2.0);
  EXPECT_FALSE(e.clamped);
  e = LookupErrorAt(map, scene, c, {6, 4, 0});  // beyond them: x = 4's, flagged
  EXPECT_DOUBLE_EQ(e.error_percent, 1.0);
  EXPECT_TRUE(e.clamped);
  e = LookupErrorAt(map, scene, c, {4, 8, 3});  // another face: clamped on y and z
  EXPECT_TRUE(e.clamped);

  map.samples[0].status = SampleStatus::kPredictedUnstable;
  e = LookupErrorAt(map, scene, c, {3, 4, 0});
  EXPECT_FALSE(e.usable);
  EXPECT_EQ(e.error_percent, -1);
  EXPECT_TRUE(LookupErrorAt(map, scene, c, {4, 4, 0}).usable);  // weight 0 on the unstable one
}

// A sliding tool takes the regions on across the face: a configuration is judged over the mapped
// nodes within LookaheadNodes of the contact node, not the node alone. The map: one primary size,
// a cheap 500 Hz secondary that diverged two nodes along x, and a dearer 1000 Hz one usable on
// all three mapped nodes.
TEST(Supervisor, ASlidingToolsConfigurationIsJudgedOverTheNodesAheadOfIt) {
  Scene scene;
  scene.mesh.nodes = 9;  // middle of the front face: (4, 4, 0)
  scene.adaptivity.primary_size = 3;
  std::array<std::vector<double>, kNumMapAxes> axes;
  const MapPoint at = PointOfScene(scene);
  for (int a = 0; a < kNumMapAxes; ++a) axes[a] = {at[a]};
  constexpr int kRate = static_cast<int>(MapAxis::kSecondaryRate);
  constexpr int kNodeX = static_cast<int>(MapAxis::kContactNodeX);
  axes[static_cast<int>(MapAxis::kSecondaryLod)] = {2};
  axes[static_cast<int>(MapAxis::kPrimarySize)] = {3};
  axes[kRate] = {500, 1000};
  axes[kNodeX] = {2, 4, 6};
  ErrorMap map = ErrorMap::MakeGrid(axes);
  ASSERT_EQ(map.samples.size(), 6u);
  for (MapSample& sample : map.samples) {
    const bool cheap = sample.point[kRate] == 500;
    sample.status =
        cheap && sample.point[kNodeX] == 6 ? SampleStatus::kDiverged : SampleStatus::kOk;
    sample.max_magnitude_percent = cheap ? 1.0 : 1.5;
    sample.cost_us_per_ms = {10, cheap ? 10.0 : 20.0, 0, 0};
  }
  const RegionConfiguration cheap{3, 2, 500};
  const RegionConfiguration dear{3, 2, 1000};

  // The tool sticking to its node: the node alone, the cheap one.
  EXPECT_EQ(LookaheadNodes(scene), 0);
  EXPECT_EQ(ChooseConfiguration(scene, &map, 2.0, std::nullopt).configuration, cheap);

  // Sliding: the cheap one diverged two nodes on, so the dear one, its error the worst ahead.
  scene.contact.model = ContactModel::kProxy;
  ASSERT_EQ(LookaheadNodes(scene), 2);
  const SupervisorDecision sliding = ChooseConfiguration(scene, &map, 2.0, std::nullopt);
  EXPECT_EQ(sliding.configuration, dear);
  EXPECT_DOUBLE_EQ(sliding.error_percent, 1.5);
  EXPECT_FALSE(sliding.clamped) << "the look ahead is clipped to the mapped nodes";
  EXPECT_NE(sliding.reason.find("within 2 nodes"), std::string::npos) << sliding.reason;
  EXPECT_TRUE(LookupErrorAt(map, scene, cheap, {4, 4, 0}).usable);
  EXPECT_FALSE(LookupErrorAt(map, scene, cheap, {4, 4, 0}, 2).usable);
  EXPECT_FALSE(LookupErrorAt(map, scene, cheap, {3, 4, 0}, 2).usable) << "x = 5: half x = 6's";
  EXPECT_TRUE(LookupErrorAt(map, scene, cheap, {3, 4, 0}, 1).usable) << "x = 2 to 4";

  // At the map's end the nodes ahead are x = 2 to 4 (x = 0 and 1 are not mapped: not clamped):
  // the cheap one again.
  scene.input.contact_node = LatticeIndex{2, 4, 0};
  const SupervisorDecision at_the_end = ChooseConfiguration(scene, &map, 2.0, std::nullopt);
  EXPECT_EQ(at_the_end.configuration, cheap);
  EXPECT_FALSE(at_the_end.clamped);

  // Where no configuration is usable over all the nodes ahead, the node alone decides.
  for (MapSample& sample : map.samples) {
    if (sample.point[kNodeX] == 6) sample.status = SampleStatus::kDiverged;
  }
  scene.input.contact_node = LatticeIndex{4, 4, 0};
  const SupervisorDecision nothing_ahead = ChooseConfiguration(scene, &map, 2.0, std::nullopt);
  EXPECT_EQ(nothing_ahead.configuration, cheap);
  EXPECT_TRUE(nothing_ahead.have_map);
  EXPECT_EQ(nothing_ahead.reason.find("within"), std::string::npos) << nothing_ahead.reason;
}

}  // namespace
}  // namespace hapticsim

namespace hapticsim {
namespace {

TEST(OverloadWatch, ARegionMissingDeadlinesForThreeSecondsIsReportedAndABurstIsNot) {
  constexpr std::int64_t kS = 1'000'000'000;
  const std::vector<double> rates{1000, 600};
  OverloadWatch watch;  // 5 % of the periods, three windows in a row
  EXPECT_EQ(watch.Check(0, rates), -1);
  // One bad second (a burst of 200 misses of the primary), then quiet: nothing.
  watch.Count(0, 200);
  EXPECT_EQ(watch.Check(kS, rates), -1);
  EXPECT_EQ(watch.Check(2 * kS, rates), -1);
  // The secondary misses 40 of 600 (6.7 %) every second: reported after the third.
  for (int s = 3; s <= 4; ++s) {
    watch.Count(1, 40);
    EXPECT_EQ(watch.Check(s * kS, rates), -1) << s;
  }
  watch.Count(1, 40);
  EXPECT_EQ(watch.Check(5 * kS, rates), 1);
  EXPECT_EQ(watch.last_misses(), 40);
  // Counting starts afresh; 25 of 600 (4.2 %) is under the share.
  for (int s = 6; s <= 9; ++s) {
    watch.Count(1, 25);
    EXPECT_EQ(watch.Check(s * kS, rates), -1) << s;
  }
  // No window closes before its second is over.
  watch.Count(0, 1000);
  EXPECT_EQ(watch.Check(9 * kS + kS / 2, rates), -1);
}

}  // namespace
}  // namespace hapticsim

namespace hapticsim {
namespace {

// Commands are input like any other: out-of-range fields and unknown commands are refused with the
// reason, and nothing refused reaches the supervisor.
TEST(CheckCommand, AcceptsWellFormedCommandsAndRefusesTheRestWithTheReason) {
  command_t c{};
  c.command = command_t::SET_ERROR_TARGET;
  c.error_target_percent = 5;
  EXPECT_EQ(CheckCommand(c, 1000).kind, CheckedCommand::Kind::kSetErrorTarget);
  for (double bad : {0.0, -3.0, 100.5, double{NAN}, double{INFINITY}}) {
    c.error_target_percent = bad;
    const CheckedCommand checked = CheckCommand(c, 1000);
    EXPECT_EQ(checked.kind, CheckedCommand::Kind::kRefused) << bad;
    EXPECT_NE(checked.refusal.find("(0, 100] %"), std::string::npos) << checked.refusal;
  }

  c = command_t{};
  c.command = command_t::PIN_CONFIGURATION;
  c.primary_size = 3, c.secondary_lod = 2, c.secondary_rate_hz = 800;
  const CheckedCommand pin = CheckCommand(c, 1000);
  ASSERT_EQ(pin.kind, CheckedCommand::Kind::kPinConfiguration);
  EXPECT_EQ(pin.pin, (RegionConfiguration{3, 2, 800}));
  for (auto [size, lod, rate] : {std::tuple{0, 2, 800.0},
                                 {3, 0, 800.0},
                                 {3, 2, 1500.0},
                                 {3, 2, 0.0},
                                 {3, 2, double{NAN}},
                                 {3, 2, 800.5},
                                 {5000, 2, 800.0}}) {
    c.primary_size = size, c.secondary_lod = lod, c.secondary_rate_hz = rate;
    const CheckedCommand checked = CheckCommand(c, 1000);
    EXPECT_EQ(checked.kind, CheckedCommand::Kind::kRefused) << size << " " << lod << " " << rate;
    EXPECT_NE(checked.refusal.find("PIN_CONFIGURATION refused"), std::string::npos);
  }

  c = command_t{};
  c.command = command_t::RELEASE_CONFIGURATION;
  EXPECT_EQ(CheckCommand(c, 1000).kind, CheckedCommand::Kind::kReleaseConfiguration);
  c.command = command_t::RESET;
  EXPECT_EQ(CheckCommand(c, 1000).kind, CheckedCommand::Kind::kReset);
  c.command = 99;
  const CheckedCommand unknown = CheckCommand(c, 1000);
  EXPECT_EQ(unknown.kind, CheckedCommand::Kind::kRefused);
  EXPECT_NE(unknown.refusal.find("99 refused: unknown"), std::string::npos) << unknown.refusal;
}

TEST(DaemonConfig, TextFromFuzzingNamingASceneFileIsRefusedNotRead) {
  EXPECT_THROW(ParseDaemonConfigText("[scene]\nfile = \"/dev/zero\"\n", "fuzz.toml", false), Error);
  EXPECT_NO_THROW(ParseDaemonConfigText("[scene]\nfile = \"\"\n", "fuzz.toml", false));
}

}  // namespace
}  // namespace hapticsim
