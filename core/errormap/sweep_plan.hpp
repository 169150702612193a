#pragma once

#include <array>
#include <cstddef>
#include <vector>

#include "core/errormap/error_map.hpp"
#include "core/errormap/sweep_grid.hpp"
#include "core/scene/scene.hpp"

namespace hapticsim {

/** A sample a run fills: its forces are `scale` × the run's (another amplitude, by linearity;
 *  another density at the same E/ρ, by similarity). */
struct SweepTarget {
  std::size_t sample = 0;
  double scale = 1;
};

/** One adaptive run (one input) and the samples it answers. */
struct SweepRun {
  MapPoint point{};  ///< where the run is made (its amplitude is the run's)
  std::vector<SweepTarget> targets;
};

/** One material and one configuration: its regions built once, for every run. */
struct SweepTask {
  MapPoint point{};  ///< material + configuration (+ the first run's input)
  std::vector<SweepRun> runs;
  /// Adaptive runs this task's runs stand for but not make, by saving (a shard sums its own).
  std::size_t saved_by_similarity = 0, saved_by_linearity = 0, saved_by_same_regions = 0;
};

/** The material and input (with the contact node) a reference run depends on. */
using ReferenceKey = std::array<double, 10>;
ReferenceKey ReferenceKeyOf(const MapPoint& point);

/**
 * The grid's tasks, in the fixed order that shards and journals number: materials outermost,
 * then contact node, spacing factor, rate and region group. Primary sizes that give the same
 * regions around a node share one task; with `linear`, one run per frequency answers every
 * amplitude; with `similar`, a material of an earlier one's E/ρ, ν, d and contrast has no tasks of
 * its own (the earlier one's runs fill its samples, forces × the density ratio).
 * @throws Error naming the contact node or configuration the grid cannot run.
 */
std::vector<SweepTask> PlanGridTasks(const Scene& base, const SweepGrid& grid, bool linear,
                                     bool similar);

/** A scattered grid's tasks: one run per point. */
std::vector<SweepTask> PlanScatteredTasks(const SweepGrid& grid);

}  // namespace hapticsim
