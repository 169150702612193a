#pragma once

#include <string>

#include "core/sweep_grid.hpp"

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

}  // namespace hapticsim
