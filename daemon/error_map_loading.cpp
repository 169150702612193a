#include "daemon/error_map_loading.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <vector>

#include "core/error.hpp"
#include "core/errormap/error_map_file.hpp"
#include "core/regions/stepping_order.hpp"
#include "core/scene/scene_toml.hpp"
#include "daemon/supervisor.hpp"

namespace hapticsim {

namespace {

std::string DescribeObject(const Scene& scene) {
  if (scene.geometry.from_file()) {
    return "geometry.file = \"" + scene.geometry.file +
           "\" at geometry.spacing_m = " + FormatReal(scene.geometry.spacing_m) + " m";
  }
  return "the built-in cube of mesh.nodes = " + std::to_string(scene.mesh.nodes) +
         ", mesh.edge = " + FormatReal(scene.mesh.edge_m) + " m";
}

std::vector<int> Labels(const Scene& scene) {
  std::vector<int> labels;
  for (const LabelMaterial& table : scene.materials) labels.push_back(table.label);
  std::sort(labels.begin(), labels.end());
  return labels;
}

}  // namespace

std::string MapObjectProblem(const Scene& scene, const ErrorMap& map) {
  if (map.provenance.scene_toml.empty()) return "";  // says no object: only MapProblem's checks
  Scene made_for;
  try {  // not its geometry file: a path from another machine, and slow to read on a reload
    made_for = ParseSceneSettings(map.provenance.scene_toml, "the map's recorded scene");
  } catch (const Error& e) {
    return std::string("its recorded scene cannot be read: ") + e.what();
  }
  const bool same_shape =
      made_for.geometry.from_file() == scene.geometry.from_file() &&
      (scene.geometry.from_file()
           ? made_for.geometry == scene.geometry
           : made_for.mesh.nodes == scene.mesh.nodes && made_for.mesh.edge_m == scene.mesh.edge_m);
  if (!same_shape) {
    return "it was made for " + DescribeObject(made_for) + ", and this scene's object is " +
           DescribeObject(scene) + ": make a map of this scene with hapticsim sweep";
  }
  if (made_for.supports != scene.supports) {
    return "it was made for the object held by other [[support]] tables than this scene's: make "
           "a map of this scene with hapticsim sweep";
  }
  if (Labels(made_for) != Labels(scene)) {
    return "it was made for the object with [[material]] tables of other labels than this "
           "scene's: make a map of this scene with hapticsim sweep";
  }
  return "";
}

std::shared_ptr<const ErrorMap> LoadUsableMap(const std::string& path, const Scene& scene) {
  auto map = std::make_shared<const ErrorMap>(LoadErrorMap(path));
  if (const std::string problem = MapObjectProblem(scene, *map); !problem.empty()) {
    throw Error("error map " + path + " refused: " + problem);
  }
  if (const std::string problem = MapProblem(scene, *map); !problem.empty()) {
    throw Error("error map " + path + " refused: " + problem);
  }
  return map;
}

std::string MapOrderWarning(const std::string& path, const ErrorMap& map) {
  if (map.provenance.stepping_order != SteppingOrderName(SteppingOrder::kSubsteps)) return "";
  return "error map " + path +
         " was swept in the substeps' order, which hapticsimd's threads do not run: where a "
         "secondary region runs at another rate in several substeps, its errors can be far below "
         "the force's (docs/regions.md). Sweep it again with hapticsim sweep, which steps the "
         "threads' order by default";
}

MapState LoadMap(const std::string& path, const Scene& scene, bool reload) {
  MapState state{path, nullptr};
  if (path.empty()) return state;
  try {
    state.map = LoadUsableMap(path, scene);
    spdlog::info(
        "error map {}: {} samples, grid '{}', made by {}, the regions stepped in the {}' "
        "order",
        path, state.map->samples.size(), state.map->provenance.grid,
        state.map->provenance.code_version, state.map->provenance.stepping_order);
    if (const std::string warning = MapOrderWarning(path, *state.map); !warning.empty()) {
      spdlog::warn("{}", warning);
    }
  } catch (const Error& e) {
    spdlog::error("{}; {}", e.what(),
                  reload ? "keeping the map loaded before"
                         : "running without an error map (forces carry error -1 and the no-map "
                           "flag)");
  }
  return state;
}

}  // namespace hapticsim
