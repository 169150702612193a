// hapticsimd: the haptic force daemon. Device input in (LCM, shared memory), force plus its
// looked-up error out at 1 kHz on real-time threads; a supervisor that chooses a configuration
// meeting the error target and moves regions that run away to equal rates; systemd notify and
// watchdog. The daemon itself is daemon/daemon.hpp; this parses the command line and runs it.
//
//   hapticsimd [--config /etc/hapticsim/hapticsimd.toml] [--check-config] [--print-config]
//
// Signals: SIGTERM/SIGINT stop cleanly; SIGHUP reloads the config's [supervisor] and [log] keys
// and the error map (a bad config or map is refused and the running one kept), then chooses the
// configuration again.
// Exit status: 0 clean stop, 2 bad configuration, 1 anything else.
#include <signal.h>
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <cstdlib>
#include <iostream>

#include "core/error.hpp"
#include "core/errormap/error_sweep.hpp"
#include "daemon/background_worker.hpp"
#include "daemon/daemon.hpp"

namespace hapticsim {
namespace {

int Serve(const DaemonArguments& args) {
  StartupConfig startup = LoadStartupConfig(args);
  if (args.print_config || args.check_config) return PrintOrCheckConfig(args, startup);
  // Signals go to the supervisor's thread only: blocked before any thread (the logger's
  // included) starts, so every thread inherits the mask and none takes the default action.
  sigset_t signals;
  sigemptyset(&signals);
  for (int s : {SIGTERM, SIGINT, SIGHUP}) sigaddset(&signals, s);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  auto logger = MakeDaemonLogger(startup.config.log_level);
  int status = 0;
  {
    Daemon daemon(args, std::move(startup));
    status = daemon.Run(signals);
  }
  logger->flush();
  spdlog::shutdown();
  return status;
}

}  // namespace
}  // namespace hapticsim

int main(int argc, char** argv) {
  hapticsim::DaemonArguments args;
  CLI::App app{
      "hapticsimd: the haptic force daemon — device input in, force and its looked-up "
      "error out at 1 kHz (LCM, host-local by default: ttl=0)",
      "hapticsimd"};
  app.add_option("--config,-c", args.config, "Configuration file (TOML)")->capture_default_str();
  app.add_flag("--check-config", args.check_config, "Validate the configuration and exit");
  app.add_flag("--print-config", args.print_config, "Print the configuration in effect and exit");
  app.add_option("--lcm-url", args.lcm_url, "Override lcm.url");
  app.add_option("--error-map", args.error_map, "Override supervisor.error_map");
  app.add_option("--duration", args.duration_s, "Stop after this many seconds (tests, soak)");
  app.add_flag("--no-port-guard", args.no_port_guard,
               "Tests and soaks only (refused unless in a network namespace with only loopback "
               "up and HAPTICSIM_SANDBOX=1, as `hapticsim soak --no-port-guard` runs it): send the "
               "simulated force without the port guard's envelope, slew ceiling and passivity "
               "controller, to show what the coupling does by itself");
  app.set_version_flag("--version", hapticsim::CodeVersion());
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : 2;
  }
  // A job may still run on a background worker that shutdown did not wait for: then leave
  // without running static destructors under it (the log flushed first).
  auto leave = [](int status) {
    if (hapticsim::AJobWasLeftRunning()) {
      spdlog::shutdown();
      std::fflush(nullptr);
      std::_Exit(status);
    }
    return status;
  };
  try {
    return leave(hapticsim::Serve(args));
  } catch (const hapticsim::Error& e) {
    std::cerr << "hapticsimd: error: " << e.what() << "\n";
    return leave(2);
  } catch (const std::exception& e) {
    std::cerr << "hapticsimd: internal error: " << e.what() << "\n";
    return leave(1);
  }
}
