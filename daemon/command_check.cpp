#include "daemon/command_check.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace hapticsim {

CheckedCommand CheckCommand(const command_t& command, double primary_rate_hz) {
  CheckedCommand out;
  std::ostringstream why;
  switch (command.command) {
    case command_t::SET_ERROR_TARGET:
      if (std::isfinite(command.error_target_percent) && command.error_target_percent > 0 &&
          command.error_target_percent <= 100) {
        out.kind = CheckedCommand::Kind::kSetErrorTarget;
        out.error_target_percent = command.error_target_percent;
        return out;
      }
      why << "SET_ERROR_TARGET " << command.error_target_percent
          << " refused: the target must be in (0, 100] %";
      break;
    case command_t::PIN_CONFIGURATION: {
      const RegionConfiguration pin{command.primary_size, command.secondary_lod,
                                    command.secondary_rate_hz};
      if (pin.primary_size >= 1 && pin.primary_size <= 1000 && pin.secondary_lod >= 1 &&
          pin.secondary_lod <= 100 && std::isfinite(pin.secondary_rate_hz) &&
          pin.secondary_rate_hz >= 1 && pin.secondary_rate_hz <= primary_rate_hz &&
          pin.secondary_rate_hz == std::floor(pin.secondary_rate_hz)) {
        out.kind = CheckedCommand::Kind::kPinConfiguration;
        out.pin = pin;
        return out;
      }
      why << "PIN_CONFIGURATION refused: primary_size " << pin.primary_size
          << " must be 1 to 1000, secondary_lod " << pin.secondary_lod
          << " 1 to 100 and secondary_rate_hz " << pin.secondary_rate_hz
          << " a whole number of Hz from 1 to " << primary_rate_hz;
      break;
    }
    case command_t::RELEASE_CONFIGURATION:
      out.kind = CheckedCommand::Kind::kReleaseConfiguration;
      return out;
    case command_t::RESET:
      out.kind = CheckedCommand::Kind::kReset;
      return out;
    default:
      why << command.command << " refused: unknown or not supported by this version";
  }
  out.kind = CheckedCommand::Kind::kRefused;
  out.refusal = why.str();
  return out;
}

bool CommandRateLimit::Admit(std::int64_t now_ns) noexcept {
  if (now_ns > last_ns_) {  // a clock that goes back refills nothing
    if (last_ns_ >= 0) {
      tokens_ =
          std::min(kBurst, tokens_ + static_cast<double>(now_ns - last_ns_) * 1e-9 * kPerSecond);
    }
    last_ns_ = now_ns;
  }
  if (tokens_ >= 1) {
    tokens_ -= 1;
    return true;
  }
  ++refused_;
  return false;
}

}  // namespace hapticsim
