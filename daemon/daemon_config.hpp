#pragma once

#include <string>
#include <vector>

#include "core/scene/scene.hpp"
#include "daemon/port_guard.hpp"

namespace hapticsim {

/**
 * hapticsimd's configuration (/etc/hapticsim/hapticsimd.toml by default). Every key is optional;
 * `hapticsimd --print-config` prints them all with their defaults.
 */
struct DaemonConfig {
  // [scene]
  std::string scene_file;  ///< scene TOML (empty: the built-in paper scene)
  Scene scene;             ///< the scene file's scene, adaptivity as configured below
  // [lcm]
  bool lcm_enabled = true;
  /// Host-local by default: ttl=0 keeps multicast on this machine.
  std::string lcm_url = "udpm://239.255.76.67:7667?ttl=0";
  /// Only with this set may lcm.url send traffic off the host (a ttl above 0, tcpq:// to another
  /// machine); the daemon then says so at start, as a warning.
  bool lcm_allow_network = false;
  std::string device_channel = "HAPTIC_DEVICE";
  std::string force_channel = "HAPTIC_FORCE";
  std::string status_channel = "HAPTIC_STATUS";
  std::string command_channel = "HAPTIC_COMMAND";
  std::string deformation_channel =
      "HAPTIC_DEFORMATION";  ///< deformation_t, at deformation_rate_hz
  /// Commands on command_channel are refused unless this is set: anyone who can send on the bus
  /// could otherwise reset the simulation or pin a configuration. `hapticsim ctl` uses [control].
  /// Set, only commands signed with the key in lcm_command_key_file are taken
  /// (ipc/command_signature.hpp).
  bool lcm_accept_commands = false;
  std::string lcm_command_key_file;  ///< the shared key of signed LCM commands (64 hex digits)
  // [control]: hapticsim ctl's Unix socket, where state-changing commands come from
  bool control_enabled = true;
  std::string control_socket = "/run/hapticsim/control.sock";
  std::string control_group;  ///< who may send commands besides root and the daemon's user
  // [shm]
  bool shm_enabled = false;  ///< the shared-memory interface for a local driver
  /// The service socket a driver connects to for its segment (ipc/service_socket.hpp)
  std::string shm_socket = "/run/hapticsim/hapticsimd.sock";
  std::string shm_group;  ///< group the driver runs in (empty: the daemon's own)
  // [supervisor]
  std::string error_map;              ///< map file (empty: none; the error is reported as -1)
  double error_target_percent = 7.0;  ///< the force-magnitude JND
  double status_rate_hz = 5;
  // [input]
  double stale_after_s = 0.05;        ///< input older than this is stale
  bool zero_force_when_stale = true;  ///< stale: render zero force (else hold the last)
  double max_speed_m_per_s = 5.0;     ///< faster jumps are rejected (no hand moves so)
  double workspace_margin_m = 0.1;    ///< accepted positions: the object's box grown by this
  // [device]: who drives the tool, and the profile the force sent obeys (PortGuard)
  /// "lcm" or "shm": the one transport whose device input is used; input on the other is
  /// rejected and counted. Empty: "shm" when shm.enabled, else "lcm".
  std::string device_input;
  PortGuardSettings port;
  // [realtime]
  int fifo_priority = 0;      ///< SCHED_FIFO priority of the region threads (0: normal)
  std::vector<int> cpus;      ///< CPUs the region threads are pinned to (empty: any)
  bool lock_memory = false;   ///< mlockall(MCL_CURRENT | MCL_FUTURE)
  bool sleep_at_rest = true;  ///< regions at rest with nothing touching them are not stepped
  // [deformation]: the deformed surface out, for a simulator or a viewer to draw
  /// Frames per second of the deformed surface (0: none; else 1 to 240), as deformation_t on LCM
  /// and in the shared-memory session; made by a thread of its own, off the real-time path.
  double deformation_rate_hz = 60;
  // [log]
  std::string log_level = "info";   ///< trace, debug, info, warn, error
  double max_log_lines_per_s = 10;  ///< rate limit of repeated warnings
};

/**
 * Reads a config file over the defaults and validates every key.
 * @throws Error naming the file, line and key when something is wrong.
 */
DaemonConfig LoadDaemonConfig(const std::string& path);

/**
 * The same from a config file's text; `origin` names it in messages. Without read_scene_file a
 * config naming a scene file is refused instead of reading it (the fuzz target: fuzzed text must
 * not open arbitrary files).
 */
DaemonConfig ParseDaemonConfigText(const std::string& text, const std::string& origin,
                                   bool read_scene_file = true);

/** The transport that owns the device input: device.input, or its default. */
std::string DeviceInputOf(const DaemonConfig& config);
/** As the log names it: "shared memory" or "LCM", the transport that owns the device input, or
 *  with `other` the one that does not. */
const char* DeviceInputName(const DaemonConfig& config, bool other = false);

/**
 * Why `url` may not be lcm.url, or "" if it may: a provider LCM has (udpm, mpudpm, tcpq, memq,
 * file), and, unless `allow_network`, traffic that stays on this host — udpm with ttl=0 (LCM's
 * default when the URL names none), tcpq to an address in 127.0.0.0/8.
 */
std::string LcmUrlProblem(const std::string& url, bool allow_network);
/** Whether `url` is a valid LCM URL that sends traffic off this host. */
bool LcmUrlLeavesHost(const std::string& url);

/** The defaults, as with an empty config file. */
DaemonConfig DefaultDaemonConfig();

/** Validates a config (ranges, the scene's adaptivity). @throws Error naming the key. */
void ValidateDaemonConfig(const DaemonConfig& config);

/** The config as TOML that LoadDaemonConfig reads back. */
std::string FormatDaemonConfig(const DaemonConfig& config);

}  // namespace hapticsim
