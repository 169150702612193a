#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "core/errormap/map_axes.hpp"

namespace hapticsim {

/** Where a sweep samples: a grid (Cartesian product of axis values) or scattered points. */
struct SweepGrid {
  std::string name;                                   ///< recorded in the map's provenance
  bool scattered = false;                             ///< Monte Carlo points instead of axes
  std::array<std::vector<double>, kNumMapAxes> axes;  ///< grid: ascending values per axis
  std::vector<MapPoint> points;                       ///< scattered: the samples

  std::size_t NumSamples() const;
};

/**
 * The paper's grid (Section V-B): ν {0.40, 0.45, 0.49}, ρ {800, 1000, 1200} kg/m³,
 * d {10, 20, 30, 40} 1/s, E {5, 10, 15, 20} kPa, amplitude {0.005, 0.010, 0.015} m,
 * frequency {0.5, 1.0, 1.25} Hz, spacing factor {1, 2, 3}, primary size {1, 2, 3, 4},
 * secondary rate {1000, 900, 800, 700, 600} Hz: 77,760 samples, all at the contact node and
 * material contrast of `scene_point` (the paper presses one node of one material).
 */
SweepGrid PaperGrid(const MapPoint& scene_point);

/**
 * Two values on every axis of the paper's grid (the ends), and two contact nodes: the scene's and
 * its first neighbour (−x, +x, −y, +y, −z, +z) that is a free surface node of the scene's mesh
 * (the scene's alone if none is); on an object of several materials, two contrasts: 1 and the
 * scene's. Under a minute on the cube.
 */
SweepGrid QuickGrid(const Scene& scene);

/**
 * The map the daemon needs for one scene: its material, the paper's inputs and every adaptive
 * configuration of the paper's grid.
 */
SweepGrid SceneGrid(const MapPoint& scene_point);

/**
 * `count` points drawn uniformly from the paper's ranges: material and input continuous; spacing
 * factor, primary size and secondary rate from the paper's values; the contact node of
 * `scene_point`. Reproducible from `seed`.
 */
SweepGrid MonteCarloGrid(int count, std::uint64_t seed, const MapPoint& scene_point);

/**
 * Checks a grid: values ascending and within each key's range.
 * @throws Error naming the axis.
 */
void ValidateGrid(const SweepGrid& grid);

}  // namespace hapticsim
