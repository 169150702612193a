// Fuzz target: the scene file parser (TOML text → validated Scene). Anything may be refused with
// an Error; nothing may crash, hang or allocate without bound.
#include <cstddef>
#include <cstdint>
#include <string>

#include "core/error.hpp"
#include "core/scene/scene_toml.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const hapticsim::Scene scene = hapticsim::ParseSceneText(text, "fuzz.toml");
    // What was accepted must print as TOML that reads back to the same scene.
    const std::string again = hapticsim::FormatSceneToml(scene);
    if (hapticsim::FormatSceneToml(hapticsim::ParseSceneText(again, "again.toml")) != again) {
      __builtin_trap();
    }
  } catch (const hapticsim::Error&) {
  }
  return 0;
}
