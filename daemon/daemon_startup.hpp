#pragma once

#include <memory>
#include <optional>
#include <string>

#include "daemon/daemon_config.hpp"
#include "ipc/command_signature.hpp"

namespace spdlog {
class logger;
}

namespace hapticsim {

/** Where hapticsimd reads its configuration unless told otherwise (--config). */
inline constexpr const char* kDefaultDaemonConfig = "/etc/hapticsim/hapticsimd.toml";

/** hapticsimd's command line (daemon/main.cpp parses it). */
struct DaemonArguments {
  std::string config = kDefaultDaemonConfig;
  bool check_config = false;
  bool print_config = false;
  std::string lcm_url;         ///< overrides lcm.url when set
  std::string error_map;       ///< overrides supervisor.error_map when set
  double duration_s = 0;       ///< stop after this long (tests, soaks); 0: until a signal
  bool no_port_guard = false;  ///< tests and soaks in a sandbox only (WhyNotASandbox)
};

/** The configuration the daemon starts with. */
struct StartupConfig {
  DaemonConfig config;
  /** The default path was asked for and does not exist: the built-in defaults run. */
  bool default_missing = false;
};

/**
 * The configuration `args` name, with their overrides, validated; --no-port-guard outside a
 * sandbox is refused here. @throws Error naming the key or file and what is wrong.
 */
StartupConfig LoadStartupConfig(const DaemonArguments& args);

/**
 * --print-config and --check-config: say the configuration, or check it (its map and command key
 * too). Returns the exit status. @throws Error naming what is wrong.
 */
int PrintOrCheckConfig(const DaemonArguments& args, const StartupConfig& startup);

/**
 * SIGHUP: the supervisor's and the log's keys (and the map's path) of the file `args` name take
 * effect in `config` now (the default logger's level with them); other changed keys are said
 * and wait for a restart. A file the loader refuses changes nothing, said in the log. Returns
 * whether it was taken.
 */
bool ReloadConfig(const DaemonArguments& args, DaemonConfig* config);

/**
 * With lcm.accept_commands, the gate that takes signed LCM commands only; without, none.
 * @throws Error when the key file is missing, readable by others or malformed.
 */
std::optional<SignedCommandGate> LcmCommandGateOf(const DaemonConfig& config);

/**
 * The daemon's logger, made the default: asynchronous (no thread of the force path waits for
 * stderr), each line prefixed with its level for journalctl -p. Make it after the signals are
 * blocked: its thread inherits the mask.
 */
std::shared_ptr<spdlog::logger> MakeDaemonLogger(const std::string& level);

}  // namespace hapticsim
