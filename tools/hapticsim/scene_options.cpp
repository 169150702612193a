#include "tools/hapticsim/scene_options.hpp"

#include "core/scene/scene_toml.hpp"

namespace hapticsim::cli {

Scene SceneOptions::Resolve() const {
  Scene scene = scene_file.empty() ? Scene{} : LoadSceneFile(scene_file);
  ApplySceneOverrides(&scene, assignments);
  return scene;
}

void AddSceneOptions(CLI::App* app, SceneOptions* options) {
  std::string keys;
  for (const SceneKeyInfo& key : SceneKeys()) {
    keys += "\n    " + std::string(key.name) + " = " + GetSceneValue(Scene{}, key.name) +
            (key.unit.empty() ? "" : " " + std::string(key.unit)) + ": " + std::string(key.meaning);
  }
  app->add_option("--scene", options->scene_file,
                  "Scene file (TOML); keys it omits keep the built-in paper scene's values")
      ->type_name("FILE.toml");
  app->add_option("--set", options->assignments,
                  "Override one scene key, repeatable (applied after --scene). Keys, with their "
                  "defaults (the paper's scene):" +
                      keys)
      ->type_name("KEY=VALUE")
      ->take_all();
  app->add_flag("--json", options->json, "Print one JSON object on stdout (units in key names)");
}

}  // namespace hapticsim::cli
