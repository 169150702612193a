#include "daemon/error_map_loading.hpp"

#include <spdlog/spdlog.h>

#include "core/error.hpp"
#include "core/errormap/error_map_file.hpp"
#include "daemon/supervisor.hpp"

namespace hapticsim {

std::shared_ptr<const ErrorMap> LoadUsableMap(const std::string& path, const Scene& scene) {
  auto map = std::make_shared<const ErrorMap>(LoadErrorMap(path));
  if (const std::string problem = MapProblem(scene, *map); !problem.empty()) {
    throw Error("error map " + path + " refused: " + problem);
  }
  return map;
}

MapState LoadMap(const std::string& path, const Scene& scene, bool reload) {
  MapState state{path, nullptr};
  if (path.empty()) return state;
  try {
    state.map = LoadUsableMap(path, scene);
    spdlog::info("error map {}: {} samples, grid '{}', made by {}", path, state.map->samples.size(),
                 state.map->provenance.grid, state.map->provenance.code_version);
  } catch (const Error& e) {
    spdlog::error("{}; {}", e.what(),
                  reload ? "keeping the map loaded before"
                         : "running without an error map (forces carry error -1 and the no-map "
                           "flag)");
  }
  return state;
}

}  // namespace hapticsim
