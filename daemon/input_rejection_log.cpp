#include "daemon/input_rejection_log.hpp"

#include <spdlog/spdlog.h>

#include "daemon/input_guard.hpp"
#include "daemon/log_line_budget.hpp"

namespace hapticsim {

InputRejectionLog::InputRejectionLog(InputCounters& counters, const DaemonConfig& config)
    : counters_(counters),
      config_(config),
      owner_name_(DeviceInputName(config)),
      other_name_(DeviceInputName(config, true)) {}

void InputRejectionLog::Read(std::int64_t now) {
  const bool may_log = LineDue(now, last_line_ns_, config_.max_log_lines_per_s);
  const auto rejection = may_log ? static_cast<InputRejection>(counters_.last_rejection.exchange(0))
                                 : InputRejection::kAccepted;
  const std::int64_t wrong_transport = counters_.inputs_wrong_transport.load();
  if (may_log && wrong_transport != wrong_transport_seen_) {
    last_line_ns_ = now;
    spdlog::warn("device input on {} refused: {} owns the input (device.input); {} refused so far",
                 other_name_, owner_name_, wrong_transport);
    wrong_transport_seen_ = wrong_transport;
  }
  if (rejection != InputRejection::kAccepted) {
    last_line_ns_ = now;
    spdlog::warn(
        "device input rejected: {} ({} rejected so far; the last accepted input stays in use)",
        InputRejectionName(rejection), counters_.inputs_rejected.load());
  }
}

}  // namespace hapticsim
