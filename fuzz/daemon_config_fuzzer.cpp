// Fuzz target: the daemon's config parser (hapticsimd.toml text → validated DaemonConfig).
#include <cstddef>
#include <cstdint>
#include <string>

#include "core/error.hpp"
#include "daemon/daemon_config.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    // A fuzzed config naming a scene file is refused rather than opening arbitrary files.
    const hapticsim::DaemonConfig config =
        hapticsim::ParseDaemonConfigText(text, "fuzz.toml", /*read_scene_file=*/false);
    const std::string again = hapticsim::FormatDaemonConfig(config);
    if (hapticsim::FormatDaemonConfig(hapticsim::ParseDaemonConfigText(again, "again.toml")) !=
        again) {
      __builtin_trap();
    }
  } catch (const hapticsim::Error&) {
  }
  return 0;
}
