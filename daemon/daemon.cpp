#include "daemon/daemon.hpp"

#include <spdlog/spdlog.h>
#include <sys/mman.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <thread>
#include <vector>

#include "core/error.hpp"
#include "core/errormap/error_sweep.hpp"
#include "core/fem/cpu_dispatch.hpp"
#include "daemon/error_map_loading.hpp"
#include "daemon/status_report.hpp"
#include "daemon/supervisor.hpp"
#include "daemon/thread_health.hpp"

namespace hapticsim {
namespace {

// A sliding tool's tip narrower than two spacings pressed deeper than a spacing dimples the surface
// it reads, and the proxy runs away over its own dimple (measured offline on a 4 cm block at
// 2.5 mm voxels, 3 mm deep, frictionless: 0.08 N lateral on the regions, 3.5 N on the
// full-resolution object, on a press of 0.06 N; a 5 mm tip: 0.05 mN,
// RegionStroke.OnALatticeFinerThanThePressIsDeep…; through hapticsimd on the phantom at 5 mm, a
// walk 8.7 mm deep: the force fell from 1.26 to 0.68 N in 3 periods). Shallower, a point tip
// strokes cleanly since the spring is taken at each step's end (3 mm on 5 mm voxels: largest step
// 0.058 N). Said rather than refused: how deep the hand goes is not known at start.
void WarnOfAPointTipOnAFineLattice(const Scene& scene, double spacing_m) {
  if (!UsesProxyContact(scene) || spacing_m >= 0.01 || scene.contact.radius_m >= 2 * spacing_m) {
    return;
  }
  spdlog::warn(
      "contact.radius = {} m on voxels of {} m: a sliding tool's tip narrower than two voxels, "
      "pressed deeper than a voxel, dimples the surface it reads and runs away over it; set "
      "contact.radius = {} m or more (docs/operations.md, \"A tool that slides\")",
      scene.contact.radius_m, spacing_m, 2 * spacing_m);
}

}  // namespace

namespace {

HapticLoop::Options LoopOptionsOf(const DaemonConfig& config, bool no_port_guard) {
  HapticLoop::Options options;
  options.stale_after_s = config.stale_after_s;
  options.zero_force_when_stale = config.zero_force_when_stale;
  options.port = config.port;
  options.fifo_priority = config.fifo_priority;
  options.cpus = config.cpus;
  options.sleep_at_rest = config.sleep_at_rest;
  options.port_guard_off = no_port_guard;
  return options;
}

}  // namespace

Daemon::Daemon(const DaemonArguments& args, StartupConfig startup)
    : args_(args), config_(std::move(startup.config)), default_missing_(startup.default_missing) {
  spdlog::info("hapticsimd {} starting; config {}; K·u kernels {}", CodeVersion(),
               default_missing_ ? "built-in defaults (no " + args_.config + ")" : args_.config,
               KernelInstructionSet());
  if (config_.lock_memory && mlockall(MCL_CURRENT | MCL_FUTURE) != 0) {
    spdlog::warn(
        "mlockall refused ({}; needs CAP_IPC_LOCK or LimitMEMLOCK=infinity): memory may be "
        "paged, running on",
        std::strerror(errno));
  }
  MapState map = LoadMap(config_.error_map, config_.scene);
  const double target = config_.error_target_percent;
  const SupervisorDecision first =
      ChooseConfiguration(config_.scene, map.map.get(), target, std::nullopt);
  spdlog::info("configuration: {}", first.reason);
  if (args_.no_port_guard) {
    spdlog::warn(
        "the port guard is OFF (--no-port-guard, a test): the simulated force goes to the device "
        "with no envelope, slew ceiling or passivity controller");
  }
  loop_ = std::make_unique<HapticLoop>(SceneWith(config_.scene, first.configuration),
                                       LoopOptionsOf(config_, args_.no_port_guard));
  loop_->SetErrorState(first.error_percent, DecisionFlags(first));
  const ContactObject& object = loop_->contact_object();
  const std::array<int, 3>& nodes = object.nodes();
  spdlog::info(
      "object: {} of the {} × {} × {} voxels of {:.4g} m occupied; {} surface nodes the tool may "
      "touch",
      object.occupied_voxels(), nodes[0] - 1, nodes[1] - 1, nodes[2] - 1, object.spacing_m(),
      object.drivable_nodes());
  const LatticeIndex contact = loop_->centre_node();
  spdlog::info(
      "contact: the regions are centred on node ({}, {}, {}) and follow the tool{}", contact[0],
      contact[1], contact[2],
      loop_->sliding_contact()
          ? fmt::format("; the tool slides (contact.model = \"proxy\": μ_s {}, μ_k {}, "
                        "{} N/m, tip radius {} m)",
                        config_.scene.contact.static_friction,
                        config_.scene.contact.kinetic_friction,
                        config_.scene.contact.stiffness_n_per_m, config_.scene.contact.radius_m)
          : std::string("; the touched node follows the tip (contact.model = \"node\")"));
  WarnOfAPointTipOnAFineLattice(config_.scene, object.spacing_m());
  StartTransports();
  if (const std::string refused = loop_->Start(); !refused.empty()) {
    spdlog::warn("real-time settings: {}running on", refused);
  }
  io_ = std::make_unique<IoThread>(*loop_, counters_, bridge_.get(), shm_.get());
  // Ready once the primary loop has run a period.
  while (loop_->monitor(kPrimaryRegion).last_done_ns() == 0) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  systemd_.Notify("READY=1\nSTATUS=serving");
  spdlog::info("serving: {} regions running", loop_->regions().num_regions());
  if (config_.deformation_rate_hz > 0) {
    deformation_.emplace(config_, *loop_, bridge_.get(), shm_.get());
  }
  events_ = std::make_unique<LoopEventLog>(*loop_, config_);
  start_ns_ = next_status_ns_ = HapticLoop::NowNs();
  supervisor_ = std::make_unique<ConfigurationSupervisor>(config_.scene, std::move(map), target,
                                                          first, *loop_);
  rejections_ = std::make_unique<InputRejectionLog>(counters_, config_);
  commands_ = std::make_unique<CommandIntake>(bridge_.get(), control_.get(), counters_, config_);
  health_ = std::make_unique<ServiceHealth>(*loop_, systemd_, start_ns_);
}

// LCM, shared memory and the control socket, as the config enables them. A control socket that
// cannot be made leaves the daemon without commands, serving on; a transport that cannot start
// ends the start.
void Daemon::StartTransports() {
  if (config_.lcm_enabled) {
    bridge_ = std::make_unique<LcmBridge>(config_, *loop_, counters_, LcmCommandGateOf(config_));
  }
  if (config_.shm_enabled) {
    shm_ = std::make_unique<ShmServer>(config_.shm_socket, config_.shm_group,
                                       config_.workspace_margin_m, config_.max_speed_m_per_s,
                                       config_.max_log_lines_per_s, *loop_, counters_,
                                       DeviceInputOf(config_) == "shm");
    spdlog::info("shared memory: drivers connect to {} (mode 0660{})", config_.shm_socket,
                 config_.shm_group.empty() ? "" : ", group " + config_.shm_group);
  }
  if (!bridge_ && !shm_) spdlog::warn("neither [lcm] nor [shm] is enabled: no device can connect");
  if (config_.control_enabled) {
    try {
      control_ = std::make_unique<ControlServer>(config_.control_socket, config_.control_group);
      spdlog::info("commands from hapticsim ctl on {} (mode 0660{})", config_.control_socket,
                   config_.control_group.empty() ? "" : ", group " + config_.control_group);
    } catch (const Error& e) {
      spdlog::warn("no hapticsim ctl: {}; serving on without commands", e.what());
    }
  }
  if (bridge_ && config_.lcm_accept_commands) {
    spdlog::warn(
        "commands on {} are accepted when signed with the key in {} (lcm.accept_commands = "
        "true): whoever can read that file can command the daemon",
        config_.command_channel, config_.lcm_command_key_file);
  }
  if (bridge_ || shm_) SayDeviceEnvelope();
}

void Daemon::SayDeviceEnvelope() const {
  spdlog::info(
      "device input from {} only (device.input); force envelope: {} N, {} N/ms slew, engage ramp "
      "{} N/ms, lift-off release {} N/ms, fault above {} N or a {} s primary stall, passivity {}",
      DeviceInputName(config_), config_.port.max_force_n, config_.port.max_force_rate_n_per_ms,
      config_.port.engage_rate_n_per_ms, config_.port.LiftOffRate(), config_.port.fault_force_n,
      config_.port.watchdog_s, config_.port.passivity ? "on" : "off");
}

int Daemon::Run(const sigset_t& signals) {
  timespec tick{0, kTick_ns};
  for (;;) {
    siginfo_t info{};
    const int signal = sigtimedwait(&signals, &info, &tick);
    if (signal > 0 && !OnSignal(signal)) break;
    const std::int64_t now = HapticLoop::NowNs();
    if (args_.duration_s > 0 && (now - start_ns_) * 1e-9 >= args_.duration_s) {
      spdlog::info("--duration {} s reached: stopping", args_.duration_s);
      break;
    }
    tick.tv_nsec = Tick(now);
  }
  Stop();
  return 0;
}

bool Daemon::OnSignal(int signal) {
  if (signal == SIGTERM || signal == SIGINT) {
    spdlog::info("{}: stopping", signal == SIGTERM ? "SIGTERM" : "SIGINT");
    return false;
  }
  if (signal == SIGHUP) {
    std::optional<double> target;
    if (!default_missing_ && ReloadConfig(args_, &config_)) target = config_.error_target_percent;
    spdlog::info("SIGHUP: reloading the error map {}", config_.error_map);
    supervisor_->OnReload(target, LoadMap(config_.error_map, config_.scene, true));
  }
  return true;
}

std::string Daemon::OnCommand(const command_t& command, const std::string& from) {
  return supervisor_->OnCommand(command, from);
}

long Daemon::Tick(std::int64_t now) {
  const LoopEventLog::Misses misses = events_->ReadDeadlines(now);
  for (int r = 0; r < loop_->regions().num_regions(); ++r) supervisor_->CountMisses(r, misses[r]);
  rejections_->Read(now);
  commands_->Drain(now, [this](const command_t& command, const std::string& from) {
    return OnCommand(command, from);
  });
  const bool move_soon = supervisor_->Tick(now);
  if (events_->ReadFaults(now)) supervisor_->RestartFromRest("force fault");
  const std::vector<Stall> stalls = health_->Stalled(now, HealthSigns());
  if (now >= next_status_ns_) UpdateStatus(now, stalls);
  health_->Report(now, stalls);
  return move_soon ? kTickBeforeAMove_ns : kTick_ns;
}

ServiceHealth::Signs Daemon::HealthSigns() const {
  return {io_->alive_ns(), supervisor_->choice_running_since_ns(),
          supervisor_->check_running_since_ns()};
}

void Daemon::UpdateStatus(std::int64_t now, const std::vector<Stall>& stalls) {
  next_status_ns_ = now + static_cast<std::int64_t>(1e9 / config_.status_rate_hz);
  std::vector<DeadlineSnapshot> snapshots;
  for (int r = 0; r < loop_->regions().num_regions(); ++r) {
    snapshots.push_back(loop_->monitor(r).TakeSnapshot());
  }
  last_status_ = MakeStatus(*loop_, snapshots, supervisor_->Shown(), supervisor_->target_percent(),
                            supervisor_->pinned(), supervisor_->map_path(), &counters_);
  last_status_.input_owner = DeviceInputOf(config_);
  last_status_.stalled_threads = DescribeStalls(stalls);
  if (bridge_) bridge_->PostStatus(last_status_);
}

void Daemon::Stop() {
  if (stopped_) return;
  stopped_ = true;
  systemd_.Notify("STOPPING=1");
  // Both background threads told at once: their destructors then wait (at most 1 s) side by side.
  supervisor_->RequestStop();
  io_->Stop();
  deformation_.reset();
  loop_->Stop();
  events_->Flush(HapticLoop::NowNs());
  spdlog::info("stopped cleanly");
}

}  // namespace hapticsim
