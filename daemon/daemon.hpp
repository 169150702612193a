#pragma once

#include <signal.h>

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "daemon/command_intake.hpp"
#include "daemon/configuration_supervisor.hpp"
#include "daemon/control_server.hpp"
#include "daemon/daemon_startup.hpp"
#include "daemon/deformation_publisher.hpp"
#include "daemon/haptic_loop.hpp"
#include "daemon/input_counters.hpp"
#include "daemon/input_rejection_log.hpp"
#include "daemon/io_thread.hpp"
#include "daemon/lcm_bridge.hpp"
#include "daemon/loop_event_log.hpp"
#include "daemon/service_health.hpp"
#include "daemon/shm_server.hpp"
#include "daemon/systemd_notify.hpp"
#include "hapticsim/status_t.hpp"

namespace hapticsim {

/**
 * hapticsimd as a whole: the haptic loop (the regions on their real-time threads, the port
 * guard), the transports (LCM, shared memory, the control socket) and the I/O thread between them
 * and the loop, and the supervisor thread's work — the configuration (ConfigurationSupervisor),
 * commands, signals, the log of what the loop did, the status message and the service's health.
 *
 * Device input never passes through here: the I/O thread hands it to the primary thread
 * wait-free, and the force goes back the same way. The supervisor sees a touch through the loop
 * (HapticLoop::wanted_contact_node) at its next Tick.
 *
 * Everything but the constructor and Stop runs on one thread, the supervisor's.
 */
class Daemon {
 public:
  /**
   * Builds every part from `startup` and starts serving: returns once the primary loop has run a
   * period, systemd told READY. @throws Error when a part cannot start (the message says what to
   * fix: LCM's route, a socket's directory, …).
   */
  Daemon(const DaemonArguments& args, StartupConfig startup);
  ~Daemon() { Stop(); }
  Daemon(const Daemon&) = delete;
  Daemon& operator=(const Daemon&) = delete;

  /**
   * Serves until SIGTERM or SIGINT arrives in `signals` (blocked in every thread, so that only
   * this one takes them) or --duration has passed; then stops. Returns the exit status.
   */
  int Run(const sigset_t& signals);
  /** A signal taken: SIGHUP reloads the config's [supervisor] and [log] keys and the error map
   *  (a bad file or map is refused and the running one kept). Returns false for one that stops. */
  bool OnSignal(int signal);
  /** A command, as LCM or hapticsim ctl bring it; the answer in words ("ok: …", "refused: …"). */
  std::string OnCommand(const command_t& command, const std::string& from);
  /** One tick of the supervisor's work at `now_ns`; returns how long until the next, ns. */
  long Tick(std::int64_t now_ns);
  /** Stops every thread, in order (systemd told STOPPING); what a second call does: nothing. */
  void Stop();

  /** The newest status message (made every 1 / supervisor.status_rate_hz, sent when LCM is on). */
  const status_t& last_status() const { return last_status_; }
  const ConfigurationSupervisor& supervisor() const { return *supervisor_; }
  HapticLoop& loop() { return *loop_; }

  /** The supervisor's tick, and its length while a move is due (a touch waits for it). */
  static constexpr long kTick_ns = 20'000'000, kTickBeforeAMove_ns = 2'000'000;

 private:
  void StartTransports();
  void SayDeviceEnvelope() const;
  void UpdateStatus(std::int64_t now_ns, const std::vector<Stall>& stalls);
  ServiceHealth::Signs HealthSigns() const;

  const DaemonArguments args_;
  DaemonConfig config_;  // the running one: SIGHUP changes its [supervisor] and [log] keys
  const bool default_missing_;
  InputCounters counters_;
  std::unique_ptr<HapticLoop> loop_;
  std::unique_ptr<LcmBridge> bridge_;
  std::unique_ptr<ShmServer> shm_;
  std::unique_ptr<ControlServer> control_;
  std::unique_ptr<IoThread> io_;
  SystemdNotifier systemd_;
  std::optional<DeformationPublisher> deformation_;  // the deformed surface out, off the RT path
  std::unique_ptr<ConfigurationSupervisor> supervisor_;
  std::unique_ptr<LoopEventLog> events_;
  std::unique_ptr<InputRejectionLog> rejections_;
  std::unique_ptr<CommandIntake> commands_;
  std::unique_ptr<ServiceHealth> health_;
  std::int64_t start_ns_ = 0, next_status_ns_ = 0;
  status_t last_status_{};
  bool stopped_ = false;
};

}  // namespace hapticsim
