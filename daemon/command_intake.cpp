#include "daemon/command_intake.hpp"

#include <spdlog/spdlog.h>

#include <optional>

#include "daemon/control_line.hpp"
#include "daemon/log_line_budget.hpp"

namespace hapticsim {

CommandIntake::CommandIntake(LcmBridge* bridge, ControlServer* control, InputCounters& counters,
                             const DaemonConfig& config)
    : bridge_(bridge), control_(control), counters_(counters), config_(config) {}

bool CommandIntake::RefusalLineDue(std::int64_t now) const {
  return LineDue(now, last_refusal_line_ns_, config_.max_log_lines_per_s);
}

void CommandIntake::Drain(std::int64_t now, const Apply& apply) {
  if (bridge_) DrainLcm(now, apply);
  if (control_) DrainControl(now, apply);
}

void CommandIntake::DrainLcm(std::int64_t now, const Apply& apply) {
  if (const LcmBridge::Refusals refusals = bridge_->CommandRefusals();
      refusals.count != lcm_refusals_logged_ && RefusalLineDue(now)) {
    last_refusal_line_ns_ = now;
    lcm_refusals_logged_ = refusals.count;
    spdlog::warn("command on {} refused: {}; {} refused so far", config_.command_channel,
                 refusals.last_reason, refusals.count);
  }
  while (std::optional<command_t> command = bridge_->PopCommand()) {
    if (!lcm_limit_.Admit(now)) {
      counters_.commands_refused.fetch_add(1);
      if (RefusalLineDue(now)) {
        last_refusal_line_ns_ = now;
        spdlog::warn("command refused: more than {} a second ({} refused so far)",
                     CommandRateLimit::kPerSecond, lcm_limit_.refused());
      }
      continue;
    }
    // Refused by its fields (out of range, unknown): counted like every other refusal.
    if (apply(*command, "LCM").rfind("refused:", 0) == 0) counters_.commands_refused.fetch_add(1);
  }
}

void CommandIntake::DrainControl(std::int64_t now, const Apply& apply) {
  // A bounded number a tick: a flood must not keep the supervisor (and the watchdog) here.
  for (std::size_t k = 0; k < ControlServer::kMaxPending; ++k) {
    std::optional<ControlRequest> request = control_->Next(now);
    if (!request) break;
    std::string error;
    const std::string who = "hapticsim ctl (pid " + std::to_string(request->peer.pid) + ", uid " +
                            std::to_string(request->peer.uid) + ")";
    std::string answer;
    if (!ctl_limit_.Admit(now)) {
      answer = "refused: more than 10 commands a second";
    } else if (const std::optional<command_t> command = ParseControlLine(request->line, &error)) {
      answer = apply(*command, who);
    } else {
      answer = "refused: " + error;
    }
    if (answer.rfind("refused:", 0) == 0) counters_.commands_refused.fetch_add(1);
    ControlServer::Answer(*request, answer);
  }
  if (control_->refused() != control_refused_seen_) {
    counters_.commands_refused.fetch_add(control_->refused() - control_refused_seen_);
    control_refused_seen_ = control_->refused();
  }
  if (control_->refused() != control_refused_logged_ && RefusalLineDue(now)) {
    last_refusal_line_ns_ = now;
    control_refused_logged_ = control_->refused();
    spdlog::warn("control socket: refused {} ({} refused so far)", control_->last_refusal(),
                 control_refused_logged_);
  }
}

}  // namespace hapticsim
