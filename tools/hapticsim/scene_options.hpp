#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "core/scene/scene.hpp"

namespace hapticsim::cli {

/** The options every scene-reading subcommand shares: --scene, --set and --json. */
struct SceneOptions {
  std::string scene_file;
  std::vector<std::string> assignments;
  bool json = false;

  /** The effective scene: defaults, then the file, then the --set overrides in order. */
  Scene Resolve() const;
};

void AddSceneOptions(CLI::App* app, SceneOptions* options);

}  // namespace hapticsim::cli
