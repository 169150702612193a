#pragma once

#include <cstdint>
#include <string>

#include "daemon/supervisor.hpp"
#include "hapticsim/command_t.hpp"

namespace hapticsim {

/** A command from HAPTIC_COMMAND after its fields were checked. */
struct CheckedCommand {
  enum class Kind { kSetErrorTarget, kPinConfiguration, kReleaseConfiguration, kReset, kRefused };
  Kind kind = Kind::kRefused;
  double error_target_percent = 0;  ///< kSetErrorTarget: in (0, 100] %
  RegionConfiguration pin;          ///< kPinConfiguration: fields in range (the supervisor
                                    ///< checks its regions can be built before it runs)
  std::string refusal;              ///< kRefused: what was wrong, for the log
};

/**
 * Checks a decoded command like every other input: a known command with fields in range, else
 * refused with the reason. Never throws. A pin that passes here still goes through the supervisor:
 * its regions are built (each within its own step limit) before it runs, and like any
 * configuration it runs under the interface controllers, the runaway watch and the port guard.
 */
CheckedCommand CheckCommand(const command_t& command, double primary_rate_hz);

/**
 * How many commands the supervisor takes: kBurst at once, then kPerSecond a second (a token
 * bucket). A person or a script changes a target or pins a configuration a few times a minute;
 * a flood (a pin at 1 kHz) is refused beyond this, and counted.
 */
class CommandRateLimit {
 public:
  static constexpr double kPerSecond = 10;
  static constexpr double kBurst = 10;

  /** Whether a command arriving at `now_ns` (CLOCK_MONOTONIC) is taken. */
  bool Admit(std::int64_t now_ns) noexcept;
  /** Commands refused so far. */
  std::int64_t refused() const noexcept { return refused_; }

 private:
  double tokens_ = kBurst;
  std::int64_t last_ns_ = -1;
  std::int64_t refused_ = 0;
};

}  // namespace hapticsim
