#pragma once

#include <string>

#include "daemon/supervisor.hpp"
#include "hapticsim/command_t.hpp"

namespace hapticsim {

/** A command from HAPTIC_COMMAND after its fields were checked. */
struct CheckedCommand {
  enum class Kind { kSetErrorTarget, kPinConfiguration, kReleaseConfiguration, kReset, kRefused };
  Kind kind = Kind::kRefused;
  double error_target_percent = 0;  ///< kSetErrorTarget: in (0, 100] %
  RegionConfiguration pin;          ///< kPinConfiguration: fields in range (stability is the
                                    ///< supervisor's to verify before it runs)
  std::string refusal;              ///< kRefused: what was wrong, for the log
};

/**
 * Checks a decoded command like every other input: a known command with fields in range, else
 * refused with the reason. Never throws. The command channel cannot push the simulation into an
 * unstable configuration: a pin that passes here is still verified by the supervisor.
 */
CheckedCommand CheckCommand(const command_t& command, double primary_rate_hz);

}  // namespace hapticsim
