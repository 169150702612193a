#include "daemon/daemon_startup.hpp"

#include <spdlog/async.h>
#include <spdlog/sinks/stdout_sinks.h>
#include <spdlog/spdlog.h>

#include <filesystem>
#include <iostream>

#include "core/error.hpp"
#include "daemon/error_map_loading.hpp"
#include "daemon/sandbox_check.hpp"

namespace hapticsim {

StartupConfig LoadStartupConfig(const DaemonArguments& args) {
  StartupConfig startup;
  startup.default_missing =
      args.config == kDefaultDaemonConfig && !std::filesystem::exists(args.config);
  startup.config = startup.default_missing ? DefaultDaemonConfig() : LoadDaemonConfig(args.config);
  if (!args.lcm_url.empty()) startup.config.lcm_url = args.lcm_url;
  if (!args.error_map.empty()) startup.config.error_map = args.error_map;
  ValidateDaemonConfig(startup.config);
  if (args.no_port_guard) {
    if (const std::string why = WhyNotASandbox(); !why.empty()) {
      throw Error("--no-port-guard is for tests and soaks only, refused: " + why);
    }
  }
  return startup;
}

int PrintOrCheckConfig(const DaemonArguments& args, const StartupConfig& startup) {
  const DaemonConfig& config = startup.config;
  if (args.print_config) std::cout << FormatDaemonConfig(config);
  if (args.check_config) {
    // The map too: a config whose map is missing or unusable would start without one.
    if (!config.error_map.empty()) {
      try {
        (void)LoadUsableMap(config.error_map, config.scene);
      } catch (const Error& e) {
        throw Error(std::string("supervisor.error_map: ") + e.what());
      }
    }
    (void)LcmCommandGateOf(config);  // and the key of signed LCM commands
    std::cout << "hapticsimd: configuration "
              << (startup.default_missing
                      ? "(built-in defaults; " + args.config + " does not exist)"
                      : args.config)
              << " is valid\n";
  }
  return 0;
}

bool ReloadConfig(const DaemonArguments& args, DaemonConfig* config) {
  try {
    DaemonConfig fresh = LoadDaemonConfig(args.config);
    if (!args.error_map.empty()) fresh.error_map = args.error_map;
    if (!args.lcm_url.empty()) fresh.lcm_url = args.lcm_url;
    config->error_target_percent = fresh.error_target_percent;
    config->error_map = fresh.error_map;
    config->status_rate_hz = fresh.status_rate_hz;
    config->max_log_lines_per_s = fresh.max_log_lines_per_s;
    config->log_level = fresh.log_level;
    spdlog::default_logger()->set_level(spdlog::level::from_str(config->log_level));
    if (FormatDaemonConfig(fresh) != FormatDaemonConfig(*config)) {
      spdlog::warn(
          "SIGHUP: {} changed keys outside [supervisor] and [log]; they take effect at the next "
          "restart",
          args.config);
    }
    return true;
  } catch (const Error& e) {
    spdlog::error("SIGHUP: config reload refused: {}; keeping the running configuration", e.what());
    return false;
  }
}

std::optional<SignedCommandGate> LcmCommandGateOf(const DaemonConfig& config) {
  if (!config.lcm_enabled || !config.lcm_accept_commands) return std::nullopt;
  try {
    return SignedCommandGate(ReadCommandKey(config.lcm_command_key_file), config.command_channel,
                             CommandClockUs());
  } catch (const Error& e) {
    throw Error(std::string("lcm.command_key_file: ") + e.what());
  }
}

std::shared_ptr<spdlog::logger> MakeDaemonLogger(const std::string& level) {
  spdlog::init_thread_pool(8192, 1);
  auto sink = std::make_shared<spdlog::sinks::stderr_sink_mt>();
  auto logger = std::make_shared<spdlog::async_logger>(
      "hapticsimd", sink, spdlog::thread_pool(), spdlog::async_overflow_policy::overrun_oldest);
  // systemd's journal adds its own time stamp; the level prefix lets journalctl -p filter.
  logger->set_pattern("%^%l%$ %v");
  logger->set_level(spdlog::level::from_str(level));
  spdlog::set_default_logger(logger);
  return logger;
}

}  // namespace hapticsim
