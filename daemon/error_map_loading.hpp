#pragma once

#include <memory>
#include <string>

#include "core/errormap/error_map.hpp"
#include "core/scene/scene.hpp"

namespace hapticsim {

/** The error map the daemon's supervisor looks up: where it came from, and the map (or none). */
struct MapState {
  std::string path;
  std::shared_ptr<const ErrorMap> map;  ///< shared with a choice being computed; null: no map
};

/**
 * Why `map` was made for another object than `scene`'s ("" when it was not): the built-in cube of
 * other mesh.* or a geometry file (or one and the other), other [[support]] tables, or other
 * [[material]] labels. Its errors are of that object's regions, so they say nothing of this one.
 * Compares the recorded scene's settings (its geometry file is not read); a map that records no
 * scene (made in memory) has no object to compare.
 */
std::string MapObjectProblem(const Scene& scene, const ErrorMap& map);

/**
 * What the daemon warns of a map swept in the substeps' order ("" for one swept in the threads'
 * order, the daemon's). Its trials stepped an exchange the daemon's threads do not run: where a
 * secondary runs at another rate in several substeps its errors can be far below the force's
 * (docs/regions.md: 2.4 % in that order, 35 % in the threads'). Such a map is still used, not
 * refused: it is the user's, and most of its configurations are the same in both orders.
 */
std::string MapOrderWarning(const std::string& path, const ErrorMap& map);

/**
 * The map at `path`, checked as the supervisor will use it with `scene` (MapProblem) and made for
 * the scene's object (MapObjectProblem).
 * @throws Error naming the file and what is wrong with it.
 */
std::shared_ptr<const ErrorMap> LoadUsableMap(const std::string& path, const Scene& scene);

/**
 * The map at `path` (none for an empty path), said in the log; a map it cannot use is said too,
 * and leaves no map — at start the daemon runs without one, on a reload (`reload`) the caller
 * keeps the one it had.
 */
MapState LoadMap(const std::string& path, const Scene& scene, bool reload = false);

}  // namespace hapticsim
