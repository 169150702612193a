#pragma once

#include <cstdint>
#include <functional>
#include <string>

#include "daemon/command_check.hpp"
#include "daemon/control_server.hpp"
#include "daemon/daemon_config.hpp"
#include "daemon/input_counters.hpp"
#include "daemon/lcm_bridge.hpp"
#include "hapticsim/command_t.hpp"

namespace hapticsim {

/**
 * Where commands come in: signed commands on LCM (lcm.accept_commands) and requests on the
 * control socket (hapticsim ctl). Each source has its own rate limit (CommandRateLimit), so an
 * LCM flood cannot crowd out ctl; a bounded number of ctl requests is taken a tick, so a flood
 * cannot keep the supervisor (and the watchdog) here. Refusals are counted in
 * InputCounters::commands_refused and said at most log.max_lines_per_s a second. Supervisor
 * thread.
 */
class CommandIntake {
 public:
  /** What a command does: acted on, it returns the answer in words ("ok: …" or "refused: …");
   *  `from` names who sent it. */
  using Apply = std::function<std::string(const command_t& command, const std::string& from)>;

  /** `bridge` and `control` may be null (that source is off). `config`: the running one. */
  CommandIntake(LcmBridge* bridge, ControlServer* control, InputCounters& counters,
                const DaemonConfig& config);
  /** Takes the commands that came since the last call, each through `apply`. */
  void Drain(std::int64_t now_ns, const Apply& apply);

 private:
  void DrainLcm(std::int64_t now_ns, const Apply& apply);
  void DrainControl(std::int64_t now_ns, const Apply& apply);
  bool RefusalLineDue(std::int64_t now_ns) const;

  LcmBridge* bridge_;
  ControlServer* control_;
  InputCounters& counters_;
  const DaemonConfig& config_;
  CommandRateLimit lcm_limit_, ctl_limit_;  // one each: an LCM flood cannot crowd out ctl
  std::int64_t last_refusal_line_ns_ = 0;
  std::int64_t lcm_refusals_logged_ = 0;
  std::int64_t control_refused_seen_ = 0, control_refused_logged_ = 0;
};

}  // namespace hapticsim
