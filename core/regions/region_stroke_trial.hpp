#pragma once

#include <functional>
#include <vector>

#include "core/regions/async_regions.hpp"
#include "core/scene/scene.hpp"
#include "core/trial/stroke_trial.hpp"

namespace hapticsim {

/** A stroke on the asynchronous regions: what the reference's gives, and where the primary went. */
struct RegionStrokeResult {
  StrokeTrialResult stroke;  ///< forces on the user and the proxy, period by period
  /** A move of the primary region under the proxy: at the end of period `period` the regions were
   *  rebuilt around `centre` and the object's motion carried over (AsyncRegions::RestoreState). */
  struct Move {
    long period = 0;
    LatticeIndex centre{};
  };
  std::vector<Move> moves;
  /** Compute time in each region's steps over the stroke (every set of regions it ran on), s. */
  std::vector<double> compute_s;
  /** The energy balance summed over the sets of regions, each from its start (the input work,
   *  damping, the interfaces' created and dissipated energy, the work the port limits refused;
   *  stored_j: the last set's). */
  EnergyAccount energy;
};

/**
 * A stroke (input.waveform = "stroke") on the scene's asynchronous regions, in virtual time: the
 * tool moved by the ContactTrajectory from the contact node's rest position, touching through a
 * ProxyContact on the primary region (AsyncRegions::StepPrimaryPushed), the proxy updated at each
 * of the primary's substeps with the tool on its path. Whenever the proxy is more than ¾ of a node
 * from the node the primary is centred on, the primary follows it: new regions around the node
 * nearest the proxy (if that node is inside the face, so its normal is the face's), started from
 * the object's motion as the old regions had it. The nodes the proxy's tip touches lie in both
 * primaries, so the force does not step at a move.
 *
 * Ends as the reference does (TrialOutcome): the proxy at the face's edge (kLeftSurface), a state
 * that is not finite, energy beyond the passivity budget or the runaway watch (kDivergedEnergy);
 * and a proxy that slid out of the primary within one period, inside the face (kDivergedContact).
 * `frames`: the whole object (AsyncRegions::CaptureState) at the start of the periods they ask for;
 * `regions_now`, if given, is called with the regions the stroke runs on, first at the start,
 * then after each move, before any frame of theirs (hapticsim simulate --vtk draws them).
 * `order`: how the regions are stepped (SteppingOrder).
 *
 * @throws Error for a scene whose regions cannot be made (ValidateScene; adaptivity off), or
 * whose adaptivity.primary_size cannot reach the tip's nodes (⌈contact.radius / h⌉ + 1, at least
 * 2).
 */
RegionStrokeResult RunRegionStroke(const Scene& scene, const TrialFrames& frames = {},
                                   const std::function<void(const AsyncRegions&)>& regions_now = {},
                                   SteppingOrder order = SteppingOrder::kSubsteps);

}  // namespace hapticsim
