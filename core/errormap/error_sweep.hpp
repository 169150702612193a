#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <string>

#include "core/errormap/error_map.hpp"
#include "core/errormap/sweep_grid.hpp"
#include "core/regions/stepping_order.hpp"
#include "core/scene/scene.hpp"

namespace hapticsim {

/** How the model behaves under scaling of the input: decides whether the amplitude axis is free. */
struct ModelTraits {
  std::string name;     ///< recorded in the map
  bool linear = false;  ///< force ∝ amplitude at fixed material and configuration
  /**
   * Dynamically similar in density: ρü + ρd·u̇ + E·K̂(ν)u = 0 with the motion prescribed at the
   * contact, so the motion depends on E/ρ, not on E and ρ apart, and the force ∝ ρ at fixed
   * E/ρ, ν and d — for the reference and every configuration alike.
   */
  bool similar_in_density = false;
};
/** The model this build solves: linear hexahedral FEM, central difference (linear). */
ModelTraits CurrentModel();

/** Where a sweep is, for a progress display. Called on the thread that called RunSweep. */
struct SweepProgress {
  std::size_t samples_done = 0;   ///< in this shard, resumed ones included
  std::size_t samples_total = 0;  ///< in this shard
  std::size_t samples_resumed = 0;
  double elapsed_s = 0;
};

struct SweepOptions {
  int jobs = 1;               ///< worker threads
  int shard_index = 0;        ///< this slice, 0-based
  int shard_count = 1;        ///< slices of the task list
  bool use_linearity = true;  ///< derive the amplitude axis when the model is linear
  bool use_similarity =
      true;  ///< materials of equal E/ρ, ν, d, contrast: run once, force scaled by ρ
  std::string journal_path;                 ///< completed tasks are appended here ("" = none)
  bool resume = false;                      ///< read the journal first and skip what it holds
  /** How the trials step the regions: hapticsimd's threads' order by default, so the map's
   *  errors are those of the force the daemon renders; or the substeps' order, the regions' own
   *  (maps made in either say which: ErrorMap::Provenance::stepping_order). */
  SteppingOrder order = SteppingOrder::kThreads;
  const std::atomic<bool>* stop = nullptr;  ///< set (e.g. by SIGINT) to stop after current tasks
  std::function<void(const SweepProgress&)> progress;
  double progress_interval_s = 0.5;
};

/** What a sweep did, and what each saving bought (counts of runs not made). */
struct SweepStats {
  std::size_t samples = 0;           ///< in this shard
  std::size_t samples_resumed = 0;   ///< taken from the journal
  std::size_t tasks = 0;             ///< (material, configuration) tasks in this shard
  std::size_t reference_trials = 0;  ///< full-resolution runs made
  std::size_t adaptive_trials = 0;   ///< adaptive runs made
  std::size_t stability_estimates =
      0;  ///< always 0: the sweep no longer estimates (scripts read it)
  std::size_t saved_by_reference_reuse = 0;  ///< reference runs not made: one per material+input
  std::size_t saved_by_similarity =
      0;  ///< adaptive runs not made: a material of equal E/ρ, ν, d, contrast
  std::size_t saved_by_linearity = 0;  ///< adaptive runs not made: other amplitudes
  std::size_t saved_by_same_regions =
      0;                                ///< adaptive runs not made: a size giving the same regions
  std::size_t saved_by_prediction = 0;  ///< always 0: nothing is refused (scripts read it)
  double reference_seconds = 0, adaptive_seconds = 0;  ///< CPU time
  double stability_seconds = 0;                        ///< always 0, as stability_estimates
  double wall_seconds = 0;
  bool interrupted = false;
};

/**
 * Makes an error map: for every sample of `grid`, the adaptive simulation of `base` at that
 * point, run by the same AsyncRegions code the daemon runs (virtual-time schedule), compared
 * with the full-resolution reference of the same material and input.
 *
 * Work is grouped into tasks of one material and one configuration: the configuration's regions
 * are built and their coupled stability estimated once, then every input is run on them. A
 * configuration predicted unstable is not simulated; its samples say so. References are shared
 * by all configurations of a material and input. On a grid, a material with the same E/ρ, ν and d
 * as an earlier one is not run at all: its samples are the earlier one's with the forces scaled
 * by the density ratio (ModelTraits::similar_in_density). Results do not depend on the job count or
 * the order tasks finish in; only the measured costs vary from run to run.
 *
 * @throws Error when the grid or a configuration is invalid, or the journal belongs to another
 *         sweep.
 */
ErrorMap RunSweep(const Scene& base, const SweepGrid& grid, const SweepOptions& options,
                  SweepStats* stats);

/** hapticsim's version and git revision, as recorded in maps. */
std::string CodeVersion();

}  // namespace hapticsim
