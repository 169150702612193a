// Fuzz target: what the daemon does with the bytes of an LCM message. The first byte picks the
// channel (device input or command); the rest is decoded by the generated code exactly as
// LcmBridge does, then checked as the daemon checks it (the signature gate, InputGuard,
// CheckCommand).
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "daemon/command_check.hpp"
#include "daemon/input_guard.hpp"
#include "hapticsim/command_t.hpp"
#include "hapticsim/device_input_t.hpp"
#include "ipc/command_signature.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  // One guard for the whole run, as the daemon keeps one: state across messages is fuzzed too.
  static hapticsim::InputGuard guard({0.25, 0.25, 0.25}, 0.05, 5.0);
  static std::int64_t now_ns = 0;
  const int channel = data[0] % 2;
  void* bytes = const_cast<std::uint8_t*>(data + 1);
  const int length = static_cast<int>(size - 1);
  if (channel == 0) {
    hapticsim::device_input_t input{};
    if (input.decode(bytes, 0, length) < 0) return 0;
    now_ns += 1'000'000;
    const hapticsim::InputRejection verdict =
        guard.Check(input.seq, {input.position[0], input.position[1], input.position[2]}, now_ns);
    // An accepted input is finite: nothing else may reach the simulation.
    if (verdict == hapticsim::InputRejection::kAccepted &&
        !(std::isfinite(input.position[0]) && std::isfinite(input.position[1]) &&
          std::isfinite(input.position[2]))) {
      __builtin_trap();
    }
  } else {
    hapticsim::command_t command{};
    if (command.decode(bytes, 0, length) < 0) return 0;
    // Fuzzed bytes do not know the key: the gate must refuse them all, with a reason.
    static hapticsim::SignedCommandGate gate(hapticsim::CommandKey{1, 2, 3}, "HAPTIC_COMMAND", 0);
    if (gate.Refusal(command, command.utime).empty()) __builtin_trap();
    const hapticsim::CheckedCommand checked = hapticsim::CheckCommand(command, 1000.0);
    using Kind = hapticsim::CheckedCommand::Kind;
    if (checked.kind == Kind::kSetErrorTarget &&
        !(checked.error_target_percent > 0 && checked.error_target_percent <= 100)) {
      __builtin_trap();
    }
    if (checked.kind == Kind::kPinConfiguration &&
        !(checked.pin.secondary_rate_hz >= 1 && checked.pin.secondary_rate_hz <= 1000)) {
      __builtin_trap();
    }
    if (checked.kind == Kind::kRefused && checked.refusal.empty()) __builtin_trap();
  }
  return 0;
}
