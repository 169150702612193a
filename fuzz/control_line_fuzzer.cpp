// Fuzz target: a request on the control socket (hapticsim ctl's words) → ParseControlLine, then
// CheckCommand as the daemon runs them. Whatever the bytes: no exception, an error that says
// something when nothing is parsed, and a command that CheckCommand accepts has fields in range.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

#include "daemon/command_check.hpp"
#include "daemon/control_line.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string line(reinterpret_cast<const char*>(data), size);
  std::string error;
  const std::optional<hapticsim::command_t> command = hapticsim::ParseControlLine(line, &error);
  if (!command) {
    if (error.empty()) __builtin_trap();
    for (const char c : error) {  // the answer and the log get printable text only
      if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7f) {
        __builtin_trap();
      }
    }
    return 0;
  }
  const hapticsim::CheckedCommand checked = hapticsim::CheckCommand(*command, 1000.0);
  using Kind = hapticsim::CheckedCommand::Kind;
  if (checked.kind == Kind::kSetErrorTarget &&
      !(checked.error_target_percent > 0 && checked.error_target_percent <= 100)) {
    __builtin_trap();
  }
  if (checked.kind == Kind::kPinConfiguration &&
      !(checked.pin.primary_size >= 1 && checked.pin.secondary_lod >= 1 &&
        std::isfinite(checked.pin.secondary_rate_hz) && checked.pin.secondary_rate_hz <= 1000)) {
    __builtin_trap();
  }
  return 0;
}
