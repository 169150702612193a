// hapticsimd: the haptic force daemon. Device input in (LCM), force plus its looked-up error out
// at 1 kHz on real-time threads; a supervisor that chooses a configuration meeting the error
// target and moves regions that run away to equal rates; systemd notify and watchdog.
//
//   hapticsimd [--config /etc/hapticsim/hapticsimd.toml] [--check-config] [--print-config]
//
// Signals: SIGTERM/SIGINT stop cleanly; SIGHUP reloads the config's [supervisor] and [log] keys
// and the error map (a bad config or map is refused and the running one kept), then chooses the
// configuration again (switched only while nothing touches the object).
// Exit status: 0 clean stop, 2 bad configuration, 1 anything else.
#include <signal.h>
#include <spdlog/async.h>
#include <spdlog/fmt/fmt.h>
#include <spdlog/sinks/stdout_sinks.h>
#include <spdlog/spdlog.h>
#include <sys/mman.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <limits>
#include <memory>
#include <optional>
#include <set>
#include <thread>

#include "core/cpu_dispatch.hpp"
#include "core/error.hpp"
#include "core/error_lookup.hpp"
#include "core/error_map_file.hpp"
#include "core/error_sweep.hpp"
#include "daemon/background_worker.hpp"
#include "daemon/black_box.hpp"
#include "daemon/command_check.hpp"
#include "daemon/control_line.hpp"
#include "daemon/control_server.hpp"
#include "daemon/daemon_config.hpp"
#include "daemon/deformation_publisher.hpp"
#include "daemon/error_map_loading.hpp"
#include "daemon/haptic_loop.hpp"
#include "daemon/input_counters.hpp"
#include "daemon/lcm_bridge.hpp"
#include "daemon/miss_logger.hpp"
#include "daemon/overload_watch.hpp"
#include "daemon/overrun_burst.hpp"
#include "daemon/regions_mover.hpp"
#include "daemon/sandbox_check.hpp"
#include "daemon/shm_server.hpp"
#include "daemon/status_report.hpp"
#include "daemon/supervisor.hpp"
#include "daemon/systemd_notify.hpp"
#include "daemon/thread_health.hpp"
#include "ipc/command_signature.hpp"

namespace hapticsim {
namespace {

constexpr const char* kDefaultConfig = "/etc/hapticsim/hapticsimd.toml";
constexpr size_t kBlackBoxCycles = 100;  // primary periods logged on a fault (0.1 s at 1 kHz)

struct Arguments {
  std::string config = kDefaultConfig;
  bool check_config = false;
  bool print_config = false;
  std::string lcm_url;
  std::string error_map;
  double duration_s = 0;
  bool no_port_guard = false;  // tests and soaks in a sandbox only (WhyNotASandbox)
};

std::shared_ptr<spdlog::logger> MakeLogger(const std::string& level) {
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

std::string FaultName(PortGuard::Fault fault, const PortGuardSettings& port) {
  switch (fault) {
    case PortGuard::Fault::kNonFinite:
      return "the simulated force is not finite";
    case PortGuard::Fault::kDivergence:
      return fmt::format("the simulated force exceeded device.fault_force_n = {} N",
                         port.fault_force_n);
    case PortGuard::Fault::kWatchdog:
      return fmt::format(
          "the primary thread was stalled for more than device.watchdog_s = {} s while force "
          "was sent",
          port.watchdog_s);
    default:
      return "unknown";
  }
}

std::int32_t DecisionFlags(const SupervisorDecision& d) {
  std::int32_t flags = 0;
  if (!d.have_map) flags |= force_flags::kNoErrorMap;
  if (d.have_map && !d.target_met) flags |= force_flags::kErrorTargetExceeded;
  if (d.clamped) flags |= force_flags::kLookupClamped;
  return flags;
}

// With lcm.accept_commands, the gate that takes signed LCM commands only; without, none.
// @throws Error when the key file is missing, readable by others or malformed.
std::optional<SignedCommandGate> LcmCommandGateOf(const DaemonConfig& config) {
  if (!config.lcm_enabled || !config.lcm_accept_commands) return std::nullopt;
  try {
    return SignedCommandGate(ReadCommandKey(config.lcm_command_key_file), config.command_channel,
                             CommandClockUs());
  } catch (const Error& e) {
    throw Error(std::string("lcm.command_key_file: ") + e.what());
  }
}

// SIGHUP: the supervisor's and the log's keys (and the map's path) take effect now; other
// changed keys are said and wait for a restart. A file the loader refuses changes nothing.
// Returns whether it was taken.
bool ReloadConfig(const Arguments& args, DaemonConfig* config, spdlog::logger& logger) {
  try {
    DaemonConfig fresh = LoadDaemonConfig(args.config);
    if (!args.error_map.empty()) fresh.error_map = args.error_map;
    if (!args.lcm_url.empty()) fresh.lcm_url = args.lcm_url;
    config->error_target_percent = fresh.error_target_percent;
    config->error_map = fresh.error_map;
    config->status_rate_hz = fresh.status_rate_hz;
    config->max_log_lines_per_s = fresh.max_log_lines_per_s;
    config->log_level = fresh.log_level;
    logger.set_level(spdlog::level::from_str(config->log_level));
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

// --print-config and --check-config: say the configuration, or check it (its map and command key
// too), and exit. @throws Error naming what is wrong.
int PrintOrCheckConfig(const Arguments& args, const DaemonConfig& config, bool default_missing) {
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
              << (default_missing ? "(built-in defaults; " + args.config + " does not exist)"
                                  : args.config)
              << " is valid\n";
  }
  return 0;
}

int Serve(const Arguments& args) {
  DaemonConfig config;
  const bool default_missing =
      args.config == kDefaultConfig && !std::filesystem::exists(args.config);
  config = default_missing ? DefaultDaemonConfig() : LoadDaemonConfig(args.config);
  if (!args.lcm_url.empty()) config.lcm_url = args.lcm_url;
  if (!args.error_map.empty()) config.error_map = args.error_map;
  ValidateDaemonConfig(config);
  if (args.no_port_guard) {
    if (const std::string why = WhyNotASandbox(); !why.empty()) {
      throw Error("--no-port-guard is for tests and soaks only, refused: " + why);
    }
  }
  if (args.print_config || args.check_config)
    return PrintOrCheckConfig(args, config, default_missing);

  // Signals go to the supervisor loop below only: blocked before any thread (the logger's
  // included) starts, so every thread inherits the mask and none takes the default action.
  sigset_t signals;
  sigemptyset(&signals);
  for (int s : {SIGTERM, SIGINT, SIGHUP}) sigaddset(&signals, s);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  auto logger = MakeLogger(config.log_level);
  spdlog::info("hapticsimd {} starting; config {}; K·u kernels {}", CodeVersion(),
               default_missing ? "built-in defaults (no " + args.config + ")" : args.config,
               KernelInstructionSet());
  if (config.lock_memory && mlockall(MCL_CURRENT | MCL_FUTURE) != 0) {
    spdlog::warn(
        "mlockall refused ({}; needs CAP_IPC_LOCK or LimitMEMLOCK=infinity): memory "
        "may be paged, running on",
        std::strerror(errno));
  }
  MapState map = LoadMap(config.error_map, config.scene);
  double target = config.error_target_percent;
  std::optional<RegionConfiguration> pinned;
  SupervisorDecision decision = ChooseConfiguration(config.scene, map.map.get(), target, pinned);
  spdlog::info("configuration: {}", decision.reason);

  HapticLoop::Options options;
  options.stale_after_s = config.stale_after_s;
  options.zero_force_when_stale = config.zero_force_when_stale;
  options.port = config.port;
  options.fifo_priority = config.fifo_priority;
  options.cpus = config.cpus;
  options.sleep_at_rest = config.sleep_at_rest;
  options.port_guard_off = args.no_port_guard;
  if (args.no_port_guard) {
    spdlog::warn(
        "the port guard is OFF (--no-port-guard, a test): the simulated force goes to the device "
        "with no envelope, slew ceiling or passivity controller");
  }
  HapticLoop loop(SceneWith(config.scene, decision.configuration), options);
  loop.SetErrorState(decision.error_percent, DecisionFlags(decision));
  spdlog::info("contact: the regions are centred on node ({}, {}, {}) and follow the tool",
               ContactNode(config.scene)[0], ContactNode(config.scene)[1],
               ContactNode(config.scene)[2]);

  const bool shm_owns_input = DeviceInputOf(config) == "shm";
  const char* owner_name = shm_owns_input ? "shared memory" : "LCM";
  const char* other_name = shm_owns_input ? "LCM" : "shared memory";
  InputCounters counters;
  std::unique_ptr<LcmBridge> bridge;
  if (config.lcm_enabled) {
    bridge = std::make_unique<LcmBridge>(config, loop, counters, LcmCommandGateOf(config));
  }
  std::unique_ptr<ShmServer> shm;
  if (config.shm_enabled) {
    shm = std::make_unique<ShmServer>(config.shm_socket, config.shm_group, config.scene.mesh,
                                      config.workspace_margin_m, config.max_speed_m_per_s,
                                      config.max_log_lines_per_s, loop, counters, shm_owns_input);
    spdlog::info("shared memory: drivers connect to {} (mode 0660{})", config.shm_socket,
                 config.shm_group.empty() ? "" : ", group " + config.shm_group);
  }
  if (!bridge && !shm) spdlog::warn("neither [lcm] nor [shm] is enabled: no device can connect");
  std::unique_ptr<ControlServer> control;
  if (config.control_enabled) {
    try {
      control = std::make_unique<ControlServer>(config.control_socket, config.control_group);
      spdlog::info("commands from hapticsim ctl on {} (mode 0660{})", config.control_socket,
                   config.control_group.empty() ? "" : ", group " + config.control_group);
    } catch (const Error& e) {
      spdlog::warn("no hapticsim ctl: {}; serving on without commands", e.what());
    }
  }
  if (bridge && config.lcm_accept_commands) {
    spdlog::warn(
        "commands on {} are accepted when signed with the key in {} (lcm.accept_commands = "
        "true): whoever can read that file can command the daemon",
        config.command_channel, config.lcm_command_key_file);
  }
  if (bridge || shm) {
    spdlog::info(
        "device input from {} only (device.input); force envelope: {} N, {} N/ms slew, engage "
        "ramp {} N/ms, fault above {} N or a {} s primary stall, passivity {}",
        owner_name, config.port.max_force_n, config.port.max_force_rate_n_per_ms,
        config.port.engage_rate_n_per_ms, config.port.fault_force_n, config.port.watchdog_s,
        config.port.passivity ? "on" : "off");
  }
  const std::string refused = loop.Start();
  if (!refused.empty()) spdlog::warn("real-time settings: {}running on", refused);
  std::atomic<bool> stop_io{false};
  std::atomic<std::int64_t> io_alive_ns{HapticLoop::NowNs()};  // the health check's sign of it
  // The I/O thread: everything that may block, at most 0.25 ms behind the primary thread. While
  // the loop is idle (regions asleep, no device) nothing needs it that often: LCM input wakes the
  // poll anyway, so it waits up to 20 ms; shared-memory input cannot wake it and is polled every
  // millisecond.
  std::thread io([&] {
    pthread_setname_np(pthread_self(), "hsim-io");
    const timespec quarter_ms{0, 250'000}, one_ms{0, 1'000'000}, idle_wait{0, 20'000'000};
    ForceRecord record;
    std::int64_t inputs_seen = -1, last_input_ns = 0;
    while (!stop_io.load()) {
      io_alive_ns.store(HapticLoop::NowNs(), std::memory_order_relaxed);
      // An input handed over lately: its answer comes within a period or two (the primary may
      // still say idle until its next period runs), so poll fast for a while whatever it says.
      const std::int64_t inputs = counters.inputs_received.load();
      const std::int64_t now = HapticLoop::NowNs();
      if (inputs != inputs_seen) last_input_ns = now;
      inputs_seen = inputs;
      const bool idle = loop.idle() && now - last_input_ns > 5'000'000;
      const timespec& wait = !idle ? quarter_ms : shm ? one_ms : idle_wait;
      if (bridge) {
        bridge->Poll(wait);
      } else {
        nanosleep(&wait, nullptr);
      }
      if (shm) shm->PollInput();
      while (loop.forces().Pop(&record)) {
        if (bridge) bridge->Publish(record);
        if (shm) shm->Publish(record);
      }
      if (bridge) bridge->PublishPendingStatus();
    }
  });

  const SystemdNotifier systemd;
  // Ready once the primary loop has run a period.
  while (loop.monitor(kPrimaryRegion).last_done_ns() == 0) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  systemd.Notify("READY=1\nSTATUS=serving");
  spdlog::info("serving: {} regions running", loop.regions().num_regions());
  std::optional<DeformationPublisher> deformation;  // the deformed surface out, off the RT path
  if (config.deformation_rate_hz > 0) deformation.emplace(config, loop, bridge.get(), shm.get());

  std::vector<MissLogger> miss_loggers;
  // One per region thread; the count changes when a reconfiguration changes the regions.
  auto match_miss_loggers = [&](std::int64_t now) {
    if (static_cast<int>(miss_loggers.size()) == loop.regions().num_regions()) return;
    for (auto& m : miss_loggers) m.Flush(now, true);
    miss_loggers.clear();
    for (int r = 0; r < loop.regions().num_regions(); ++r) {
      miss_loggers.emplace_back(loop.regions().partition().RegionName(r),
                                config.max_log_lines_per_s);
    }
  };
  match_miss_loggers(HapticLoop::NowNs());
  const std::int64_t start_ns = HapticLoop::NowNs();
  std::int64_t next_status_ns = start_ns, next_watchdog_ns = start_ns;
  std::int64_t faults_seen = 0, rearms_seen = 0, runaways_seen = 0, last_rejection_line_ns = 0;
  std::int64_t regions_since_ns = start_ns, health_reconfigurations = 0;
  bool health_asleep = false;
  StallReport stall_report;  // the stalled threads, as last logged and told to systemd
  std::int64_t wrong_transport_seen = 0;
  CommandRateLimit command_limit, ctl_limit;  // one each: an LCM flood cannot crowd out ctl
  std::int64_t last_command_refusal_ns = 0, lcm_refusals_logged = 0;
  std::int64_t control_refused_seen = 0, control_refused_logged = 0;
  BlackBox black_box(kBlackBoxCycles);
  std::int64_t last_fault_dump_ns = -1;  // none yet (CLOCK_MONOTONIC starts at boot)
  OverrunBurst overrun(HapticLoop::NowNs());
  // New choices are made on one background thread (building regions takes milliseconds): the
  // tick never waits, and no command makes a thread.
  BackgroundWorker<SupervisorDecision> chooser("hsim-choose");
  std::optional<RegionConfiguration> choice_pin;  // the pin the newest choice was asked with
  std::optional<SupervisorDecision> pending;      // chosen, waiting for the tool to be away
  bool choice_for_overload = false;               // the running choice is for deadlines
  // The scene as the regions run it: centred on the node the tool last touched. A choice is made
  // for that node — its error looked up there, its regions built around it.
  auto scene_at_centre = [&] {
    Scene scene = config.scene;
    scene.input.contact_node = loop.centre_node();
    return scene;
  };
  // The nodes a choice was made for since the target, the map or the pin last changed: around
  // each, the supervisor chooses once. The cost ceiling an overload set holds as long (deadlines
  // before accuracy: a choice for a node does not bring the dear configuration back).
  std::set<LatticeIndex> chosen_for_nodes{ContactNode(config.scene)};
  double cost_ceiling = std::numeric_limits<double>::infinity();
  auto start_choice = [&](const std::optional<RegionConfiguration>& pin) {
    choice_pin = pin;
    chosen_for_nodes.insert(loop.centre_node());
    chooser.Submit([scene = scene_at_centre(), m = map.map, target, pin, cost_ceiling] {
      return ChooseConfiguration(scene, m.get(), target, pin, cost_ceiling);
    });
  };
  // A new target, map or pin: every node may be chosen for again, at any cost.
  auto choose_again = [&](const std::optional<RegionConfiguration>& pin) {
    chosen_for_nodes.clear();
    cost_ceiling = std::numeric_limits<double>::infinity();
    choice_for_overload = false;
    start_choice(pin);
  };
  // The regions run mover.placement(): the decision's configuration, or its equal-rate fallback
  // where the decision's ran away around the node they are centred on.
  RegionsMover mover(config.scene, {{decision.configuration, true, false}, loop.centre_node()});
  auto active = [&mover]() -> const RegionConfiguration& {
    return mover.placement().centred.configuration;
  };
  // The error the status reports: the decision's, looked up again for the configuration running
  // and the node the regions are centred on — interpolated between mapped contact nodes, the
  // nearest mapped one's beyond them (flagged clamped). Where the map has no finite error the
  // status says -1 % and "target exceeded": accuracy unknown is not accuracy met.
  // The status message shows the same (reported_*).
  double reported_error = decision.error_percent;
  bool reported_target_met = decision.target_met;
  auto report_error = [&] {
    std::int32_t flags = DecisionFlags(decision) | (pending ? force_flags::kReconfiguring : 0);
    double error = decision.error_percent;
    if (decision.have_map && map.map) {
      const NodeError here = LookupErrorAt(*map.map, config.scene, active(), loop.centre_node());
      error = here.error_percent;
      flags &= ~(force_flags::kLookupClamped | force_flags::kErrorTargetExceeded);
      if (here.clamped) flags |= force_flags::kLookupClamped;
      if (!here.usable || error > target) flags |= force_flags::kErrorTargetExceeded;
    }
    reported_error = error;
    reported_target_met = decision.have_map && !(flags & force_flags::kErrorTargetExceeded);
    loop.SetErrorState(error, flags);
  };
  // Around the node the regions moved to, the configuration may miss the target that it met
  // where it was chosen (a box cut by the object's edge, a coarser neighbourhood): choose again
  // for that node, once per node. What is chosen switches like any other.
  auto choose_for_centre_if_missed = [&] {
    const LatticeIndex& node = loop.centre_node();
    if (reported_target_met || !decision.have_map || !map.map || pinned || chooser.busy() ||
        pending || chosen_for_nodes.count(node)) {
      return;
    }
    spdlog::warn(
        "around contact node ({}, {}, {}) the looked-up error of {} is {} % against the target "
        "{} %: choosing again for this node",
        node[0], node[1], node[2], DescribeConfiguration(active()),
        reported_error < 0 ? std::string("unknown") : fmt::format("{:.3g}", reported_error),
        target);
    start_choice(std::nullopt);
  };
  // Restarts the regions from rest where they are: the tool must lift off before it feels force.
  auto restart_from_rest = [&](const char* why) {
    try {
      loop.Reconfigure(SceneWith(config.scene, active(), loop.centre_node()));
    } catch (const Error& e) {
      // Only a hung primary thread gets here (the scene is the running one): the watchdog's
      // pings stop and systemd restarts the daemon.
      spdlog::error("{}: restarting the regions failed: {}", why, e.what());
    }
  };
  OverloadWatch overload;  // a region missing deadlines second after second
  // Per region, as last logged.
  std::array<std::int64_t, HapticLoop::kMaxRegions> stalls_seen{}, skipped_seen{};
  bool boundary_stale = false;  // the secondary region has not run for kStaleBoundary_s
  std::int64_t last_overload_line_ns = 0;
  // The cost of a configuration the map has nothing cheaper than: not asked again.
  double cheapest_cost_us_per_ms = -1;
  std::optional<LatticeIndex> hover_node;  // the node the tool hovers over, and since when
  std::int64_t hover_since_ns = 0;
  constexpr double kHoverBeforeRecentre_s = 0.2;      // not every node a passing tool crosses
  constexpr double kSettleBeforeReconfigure_s = 1.0;  // e^(−d t / 2) < 1 % at d = 10 1/s
  // The regions where the mover says: moved now (checked before, or to be checked behind them),
  // demoted to equal rates where they ran away, or moved back where they cannot run.
  auto apply_move = [&](const RegionsMover::Outcome& moved, std::int64_t now) {
    using Kind = RegionsMover::Outcome::Kind;
    spdlog::log(moved.kind == Kind::kMoveBack ? spdlog::level::err
                : moved.kind == Kind::kDemote ? spdlog::level::warn
                                              : spdlog::level::info,
                "{}", moved.Describe());
    if (moved.moves()) {
      try {
        loop.Reconfigure(SceneWith(config.scene, moved.to.centred.configuration, moved.to.node),
                         moved.CarriesMotionFrom(loop.centre_node())
                             ? HapticLoop::Handover::kCarryMotion
                             : HapticLoop::Handover::kRampIn);
      } catch (const Error&) {
        mover.NotApplied(moved);  // a demotion or a move back is tried again at the next tick
        throw;
      }
    }
    mover.Applied(moved);
    if (!moved.moves()) return;
    // The pending decision this move was asked for: a newer choice may have replaced or
    // dropped it while the move was being verified; then it is not applied.
    if (moved.request.applies_pending && pending &&
        pending->configuration == moved.request.configuration) {
      decision = *pending;
      pending.reset();
      spdlog::info("reconfigured: {}", decision.reason);
    }
    match_miss_loggers(now);
    overload.Reset(now);
    report_error();
    choose_for_centre_if_missed();
  };
  const double primary_period_s = loop.monitor(kPrimaryRegion).TakeSnapshot().period_s;
  // Every thread's newest sign of life. New region threads, or ones just woken, get a moment
  // before the check expects them to have run: read here, just before each check, so a command
  // that woke the regions earlier in the same tick does not make them look stalled since sleep.
  auto health_beats = [&](std::int64_t now) {
    const bool asleep = loop.asleep();  // read once: a wake between two reads would be missed
    if (loop.reconfigurations() != health_reconfigurations || (health_asleep && !asleep)) {
      regions_since_ns = now;
      health_reconfigurations = loop.reconfigurations();
    }
    health_asleep = asleep;
    return HealthBeats(loop, primary_period_s, io_alive_ns.load(std::memory_order_relaxed),
                       regions_since_ns, asleep, chooser.running_since_ns(),
                       mover.running_since_ns());
  };
  // A checked command, from LCM or hapticsim ctl: acted on, and what happened in words (the
  // answer ctl prints; the log says it too).
  auto apply_command = [&](const command_t& command, const std::string& from) -> std::string {
    const CheckedCommand checked = CheckCommand(command, PrimaryRateHz(config.scene));
    switch (checked.kind) {
      case CheckedCommand::Kind::kSetErrorTarget:
        target = checked.error_target_percent;
        decision.target_met = decision.have_map && decision.error_percent <= target;
        report_error();
        if (decision.have_map && decision.error_percent >= 0) {
          spdlog::info(
              "error target set to {} % by {}: the active configuration's {} % {}; choosing "
              "again",
              target, from, decision.error_percent,
              decision.target_met ? "meets it" : "EXCEEDS it");
        } else {
          spdlog::info(
              "error target set to {} % by {}: the active configuration's error is unknown (no "
              "error map, or none for this node); choosing again",
              target, from);
        }
        choose_again(pinned);
        return "ok: error target " + FormatReal(target) + " %; choosing again";
      case CheckedCommand::Kind::kPinConfiguration:
        spdlog::info(
            "command PIN_CONFIGURATION from {}: verifying primary_size {}, secondary_lod {}, "
            "secondary_rate {} Hz",
            from, checked.pin.primary_size, checked.pin.secondary_lod,
            checked.pin.secondary_rate_hz);
        choose_again(checked.pin);
        return "ok: verifying the pin (status says pinned once it runs; the log says why not)";
      case CheckedCommand::Kind::kReleaseConfiguration:
        spdlog::info("command RELEASE_CONFIGURATION from {}: choosing freely again", from);
        pinned.reset();
        choose_again(std::nullopt);
        return "ok: released; choosing freely again";
      case CheckedCommand::Kind::kReset:
        spdlog::info("command RESET from {}: the simulation restarts from rest", from);
        restart_from_rest("RESET");
        return "ok: the simulation restarts from rest";
      case CheckedCommand::Kind::kRefused:
        spdlog::warn("command from {} {}", from, checked.refusal);
        return "refused: " + checked.refusal;
    }
    return "refused: unknown";
  };
  constexpr long kTick_ns = 20'000'000, kTickBeforeAMove_ns = 2'000'000;
  timespec tick{0, kTick_ns};
  for (;;) {
    siginfo_t info{};
    const int signal = sigtimedwait(&signals, &info, &tick);
    if (signal == SIGTERM || signal == SIGINT) {
      spdlog::info("{}: stopping", signal == SIGTERM ? "SIGTERM" : "SIGINT");
      break;
    }
    if (signal == SIGHUP) {
      if (!default_missing && ReloadConfig(args, &config, *logger)) {
        target = config.error_target_percent;
      }
      spdlog::info("SIGHUP: reloading the error map {}", config.error_map);
      MapState reloaded = LoadMap(config.error_map, config.scene, true);
      if (reloaded.map || config.error_map.empty()) map = std::move(reloaded);
      report_error();  // the new target or map, until the new choice replaces the decision
      choose_again(pinned);
    }
    const std::int64_t now = HapticLoop::NowNs();
    if (args.duration_s > 0 && (now - start_ns) * 1e-9 >= args.duration_s) {
      spdlog::info("--duration {} s reached: stopping", args.duration_s);
      break;
    }
    black_box.Drain(loop);
    // A secondary region that stalled held its state over the periods it missed (HapticLoop).
    for (int r = 1; r < loop.regions().num_regions(); ++r) {
      if (loop.stalls(r) == stalls_seen[r]) continue;
      spdlog::warn(
          "{} region stalled: it held its state over {} of its periods instead of stepping them "
          "late (the primary held its boundary meanwhile); {} stall(s) so far",
          loop.regions().partition().RegionName(r), loop.skipped_periods(r) - skipped_seen[r],
          loop.stalls(r));
      stalls_seen[r] = loop.stalls(r);
      skipped_seen[r] = loop.skipped_periods(r);
    }
    // A secondary thread that does not run at all: the primary renders on its held boundary.
    const double boundary_age_s = loop.regions().primary_boundary_age_s();
    if (boundary_age_s > HapticLoop::kStaleBoundary_s && !boundary_stale) {
      spdlog::error(
          "the primary's boundary from the secondary region is {:.2f} s old: its thread is not "
          "running; the primary renders on the held boundary (the primary region alone, stable "
          "by its own limit), its forces flagged boundary stale",
          boundary_age_s);
      boundary_stale = true;
    } else if (boundary_age_s < HapticLoop::kStaleBoundary_s && boundary_stale) {
      spdlog::info("the secondary region runs again (its boundary is {:.1f} ms old)",
                   boundary_age_s * 1e3);
      boundary_stale = false;
    }
    for (int r = 0; r < loop.regions().num_regions(); ++r) {
      DeadlineEvent event;
      int misses = 0;
      while (loop.monitor(r).PopEvent(&event)) miss_loggers[r].Add(event), ++misses;
      overload.Count(r, misses);
      miss_loggers[r].Flush(now);
      // A primary that overruns again and again is a fault worth the black box.
      if (r != kPrimaryRegion) continue;
      if (const std::optional<std::string> burst = overrun.Count(misses, now)) {
        black_box.Dump(*burst);
      }
    }
    // Rejections: at most log.max_lines_per_s lines each; the counts are in every status message.
    auto line_due = [&](std::int64_t last_line_ns) {
      return (now - last_line_ns) * 1e-9 >= 1.0 / config.max_log_lines_per_s;
    };
    const bool may_log = line_due(last_rejection_line_ns);
    const auto rejection = may_log
                               ? static_cast<InputRejection>(counters.last_rejection.exchange(0))
                               : InputRejection::kAccepted;
    const std::int64_t wrong_transport = counters.inputs_wrong_transport.load();
    if (may_log && wrong_transport != wrong_transport_seen) {
      last_rejection_line_ns = now;
      spdlog::warn(
          "device input on {} refused: {} owns the input (device.input); {} refused so far",
          other_name, owner_name, wrong_transport);
      wrong_transport_seen = wrong_transport;
    }
    if (rejection != InputRejection::kAccepted) {
      last_rejection_line_ns = now;
      spdlog::warn(
          "device input rejected: {} ({} rejected so far; the last accepted input "
          "stays in use)",
          InputRejectionName(rejection), counters.inputs_rejected.load());
    }
    if (bridge) {
      if (const LcmBridge::Refusals refusals = bridge->CommandRefusals();
          refusals.count != lcm_refusals_logged && line_due(last_command_refusal_ns)) {
        last_command_refusal_ns = now;
        lcm_refusals_logged = refusals.count;
        spdlog::warn("command on {} refused: {}; {} refused so far", config.command_channel,
                     refusals.last_reason, refusals.count);
      }
      while (std::optional<command_t> command = bridge->PopCommand()) {
        if (!command_limit.Admit(now)) {
          counters.commands_refused.fetch_add(1);
          if (line_due(last_command_refusal_ns)) {
            last_command_refusal_ns = now;
            spdlog::warn("command refused: more than {} a second ({} refused so far)",
                         CommandRateLimit::kPerSecond, command_limit.refused());
          }
          continue;
        }
        apply_command(*command, "LCM");
      }
    }
    if (control) {
      // A bounded number a tick: a flood must not keep the supervisor (and the watchdog) here.
      for (std::size_t k = 0; k < ControlServer::kMaxPending; ++k) {
        std::optional<ControlRequest> request = control->Next(now);
        if (!request) break;
        std::string error;
        const std::string who = "hapticsim ctl (pid " + std::to_string(request->peer.pid) +
                                ", uid " + std::to_string(request->peer.uid) + ")";
        std::string answer;
        if (!ctl_limit.Admit(now)) {
          answer = "refused: more than 10 commands a second";
        } else if (const std::optional<command_t> command =
                       ParseControlLine(request->line, &error)) {
          answer = apply_command(*command, who);
        } else {
          answer = "refused: " + error;
        }
        if (answer.rfind("refused:", 0) == 0) counters.commands_refused.fetch_add(1);
        ControlServer::Answer(*request, answer);
      }
      if (control->refused() != control_refused_seen) {
        counters.commands_refused.fetch_add(control->refused() - control_refused_seen);
        control_refused_seen = control->refused();
      }
      if (control->refused() != control_refused_logged && line_due(last_command_refusal_ns)) {
        last_command_refusal_ns = now;
        control_refused_logged = control->refused();
        spdlog::warn("control socket: refused {} ({} refused so far)", control->last_refusal(),
                     control_refused_logged);
      }
    }
    if (std::optional<BackgroundWorker<SupervisorDecision>::Outcome> outcome = chooser.Take()) {
      if (outcome->result) {
        SupervisorDecision chosen = std::move(*outcome->result);
        if (choice_pin) spdlog::info("configuration pinned");
        pinned = choice_pin;
        if (chosen.configuration == decision.configuration) {
          spdlog::info("configuration kept: {}", chosen.reason);
          decision = chosen;
          pending.reset();
        } else {
          spdlog::info(
              "{} configuration: {}; switching once it is checked around the contact "
              "node, carrying the object's motion over",
              pinned ? "pinned" : "better", chosen.reason);
          pending = chosen;
        }
        report_error();
      } else {
        if (choice_for_overload) cheapest_cost_us_per_ms = decision.cost_us_per_ms;
        spdlog::error("{} failed: {}; keeping the active configuration",
                      choice_pin ? "pinning a configuration" : "choosing a configuration",
                      outcome->error);
      }
      choice_for_overload = false;
      choose_for_centre_if_missed();  // the regions may have moved while it was being made
    }
    // Moving the regions — to the pending configuration, or onto the node the tool touches or
    // hovers over. A new configuration around the same node switches as soon as it is checked,
    // in contact too: the object's motion carries over and the force is held meanwhile
    // (Handover::kCarryMotion). Onto a hovered node only after the object has settled, as the
    // regions restart from rest there. A touch on another node moves them at once (zero force,
    // flagged, for the few periods until they are there; checked behind them), then ramps its
    // force in; it may give up a check still running.
    const bool settled = (now - loop.last_contact_ns()) * 1e-9 >= kSettleBeforeReconfigure_s;
    const std::optional<LatticeIndex> wanted = loop.wanted_contact_node();
    if (wanted != hover_node) hover_node = wanted, hover_since_ns = now;
    const bool waiting = loop.contact_waiting();
    // Where a pending configuration goes: a hovered node once the object has settled, else here.
    const LatticeIndex pending_node =
        settled ? wanted.value_or(loop.centre_node()) : loop.centre_node();
    if (!mover.busy() || (waiting && mover.may_interrupt())) {
      std::optional<RegionsMover::Request> request;
      if (pending && !waiting) {
        request = {pending->configuration, pending_node, true, false};
      } else if (wanted && *wanted != loop.centre_node() &&
                 (waiting ||
                  (settled && (now - hover_since_ns) * 1e-9 >= kHoverBeforeRecentre_s))) {
        request = {decision.configuration, *wanted, false, waiting};
      }
      if (request && mover.may_ask(*request)) mover.Ask(*request, now);
    }
    if (loop.runaways() > runaways_seen) {  // off a configuration whose state outgrew its balance
      runaways_seen = loop.runaways();
      mover.OnRunaway(now, loop.last_runaway());  // the Poll below moves them
    }
    try {
      if (const std::optional<RegionsMover::Outcome> moved = mover.Poll(now)) {
        apply_move(*moved, now);
      }
    } catch (const Error& e) {
      spdlog::error("moving the regions failed: {}; they stay where they are", e.what());
      if (pending && !mover.may_ask({pending->configuration, pending_node, true})) {
        pending.reset();  // refused around this node: not asked again
      }
      report_error();
    }
    // A touch waiting for its regions, or a tool about to touch another node, is served within a
    // few milliseconds (the move is at the next tick); otherwise the tick is slower.
    const bool move_soon = wanted && *wanted != loop.centre_node() &&
                           mover.may_ask({decision.configuration, *wanted, false, true});
    tick.tv_nsec = move_soon ? kTickBeforeAMove_ns : kTick_ns;
    // Deadlines before accuracy: a region that keeps missing them gets a cheaper configuration
    // (the map's measured costs), switched like any other.
    std::vector<double> rates_hz;
    for (int r = 0; r < loop.regions().num_regions(); ++r) {
      rates_hz.push_back(loop.regions().schedule(r).rate_hz);
    }
    if (const int region = overload.Check(now, rates_hz); region >= 0) {
      const std::string name = loop.regions().partition().RegionName(region);
      const bool nothing_cheaper = decision.cost_us_per_ms == cheapest_cost_us_per_ms;
      if (decision.have_map && !pinned && !chooser.busy() && !nothing_cheaper) {
        spdlog::error("{}", ChoosingCheaperLine(name, overload.last_misses(), rates_hz[region],
                                                decision.cost_us_per_ms));
        cost_ceiling = decision.cost_us_per_ms;
        choice_for_overload = true;
        start_choice(std::nullopt);
      } else if (now - last_overload_line_ns > 60'000'000'000) {
        last_overload_line_ns = now;
        spdlog::error("{}",
                      CannotChooseCheaperLine(name, overload.last_misses(),
                                              pinned              ? "a configuration is pinned"
                                              : nothing_cheaper   ? "the map has nothing cheaper"
                                              : decision.have_map ? "a choice is being made"
                                                                  : "no error map"));
      }
    }
    if (loop.force_faults() > faults_seen) {
      faults_seen = loop.force_faults();
      if (last_fault_dump_ns < 0 || now - last_fault_dump_ns > 10'000'000'000) {  // 1 per 10 s
        black_box.Drain(loop);
        black_box.Dump("force fault");
        last_fault_dump_ns = now;
      }
      spdlog::error(
          "force fault latched ({}): the force ramps to zero and stays there; the simulation "
          "restarts from rest and the fault re-arms once the tool is out of the object "
          "({} fault(s) so far)",
          FaultName(loop.last_fault(), config.port), faults_seen);
      restart_from_rest("force fault");
    }
    if (loop.rearms() > rearms_seen) {
      rearms_seen = loop.rearms();
      spdlog::warn(
          "force fault re-armed: the tool is out of the object and the simulation restarted "
          "from rest; the next touch engages from zero force");
    }
    if (now >= next_status_ns) {
      next_status_ns = now + static_cast<std::int64_t>(1e9 / config.status_rate_hz);
      std::vector<DeadlineSnapshot> snapshots;
      for (int r = 0; r < loop.regions().num_regions(); ++r) {
        snapshots.push_back(loop.monitor(r).TakeSnapshot());
      }
      if (bridge) {
        SupervisorDecision shown = decision;
        shown.configuration = active();
        shown.error_percent = reported_error;  // for the node the regions are centred on
        shown.target_met = reported_target_met;
        status_t status =
            MakeStatus(loop, snapshots, shown, target, pinned.has_value(), map.path, &counters);
        status.input_owner = DeviceInputOf(config);
        status.stalled_threads = DescribeStalls(StalledThreads(health_beats(now), now));
        bridge->PostStatus(status);
      }
    }
    // Every thread the force depends on, by its newest sign of life. A stalled primary or I/O
    // thread (no force computed, or none reaching the device) stops the watchdog pings, so
    // systemd restarts the daemon; a stalled secondary is rendered around (the primary holds its
    // boundary, every answer flagged boundary stale); a job that never ends is reported.
    const std::vector<Stall> stalls = StalledThreads(health_beats(now), now);
    if (const std::optional<std::string> stalled = stall_report.Due(stalls, now)) {
      if (stalled->empty()) {
        spdlog::info("health: every thread runs again");
      } else {
        spdlog::error("health: stalled: {}{}", *stalled,
                      AnyOnForcePath(stalls) ? "; the systemd watchdog is not pinged" : "");
      }
      systemd.Notify(stalled->empty() ? "STATUS=serving" : "STATUS=stalled: " + *stalled);
    }
    if (systemd.watchdog_interval_s() > 0 && now >= next_watchdog_ns && !AnyOnForcePath(stalls)) {
      systemd.Notify("WATCHDOG=1");
      next_watchdog_ns = now + static_cast<std::int64_t>(systemd.watchdog_interval_s() * 0.5e9);
    }
  }
  systemd.Notify("STOPPING=1");
  // Both background threads told at once: their destructors then wait (at most 1 s) side by side.
  chooser.RequestStop();
  mover.RequestStop();
  stop_io = true;
  if (io.joinable()) io.join();
  deformation.reset();
  loop.Stop();
  for (auto& m : miss_loggers) m.Flush(HapticLoop::NowNs(), true);
  spdlog::info("stopped cleanly");
  logger->flush();
  spdlog::shutdown();
  return 0;
}

}  // namespace
}  // namespace hapticsim

int main(int argc, char** argv) {
  hapticsim::Arguments args;
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
  // A stability estimate may still run on a worker that shutdown did not wait for: then leave
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
