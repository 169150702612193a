#pragma once

#include <string>

#include "core/scene/scene.hpp"
#include "core/errormap/sweep_grid.hpp"

namespace hapticsim {

/**
 * Reads a user's grid (TOML): an [axes] table of value lists, keyed by the axis name or scene
 * key, e.g.
 *
 *   [axes]
 *   poisson_ratio = [0.40, 0.49]
 *   "adaptivity.secondary_rate" = [600.0, 1000.0]
 *
 * Axes the file leaves out take their single value from `base` (the sweep's scene).
 * @throws Error naming the file, line and key when the file is malformed, a key unknown or a
 *         list not strictly increasing.
 */
SweepGrid LoadGridFile(const std::string& path, const MapPoint& base);

/**
 * The grid a user names on the command line: "paper", "quick", "scene" (the scene's material),
 * a FILE.toml, or `monte_carlo` > 0 points drawn with `seed`.
 * @throws Error listing the choices.
 */
SweepGrid ChooseSweepGrid(const std::string& name, int monte_carlo, std::uint64_t seed,
                          const Scene& scene);

}  // namespace hapticsim
