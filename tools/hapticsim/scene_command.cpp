#include <iostream>
#include <nlohmann/json.hpp>

#include "core/scene/scene_toml.hpp"
#include "tools/hapticsim/command.hpp"
#include "tools/hapticsim/scene_options.hpp"

namespace hapticsim::cli {
namespace {

int Run(const SceneOptions& options) {
  const Scene scene = options.Resolve();
  if (options.json) {
    // Key names are the scene keys themselves, so a script can pass them back to --set; the
    // units sit beside them.
    nlohmann::json values, units;
    for (const SceneKeyInfo& key : SceneKeys()) {
      const std::string name(key.name);
      const std::string text = GetSceneValue(scene, name);
      if (text.front() == '"') {
        values[name] = text.substr(1, text.size() - 2);
      } else {
        values[name] = nlohmann::json::parse(text == "inf" ? "null" : text);
      }
      units[name] = key.unit;
    }
    std::cout << nlohmann::json{{"scene", values}, {"units", units}}.dump(2) << "\n";
  } else {
    std::cout << FormatSceneToml(scene);
  }
  return kExitOk;
}

}  // namespace

Command AddSceneCommand(CLI::App& parent) {
  auto options = std::make_shared<SceneOptions>();
  CLI::App* app = parent.add_subcommand(
      "scene",
      "Print the effective scene (built-in defaults, --scene file, --set overrides) as TOML");
  AddSceneOptions(app, options.get());
  return {app, [options] { return Run(*options); }};
}

}  // namespace hapticsim::cli
