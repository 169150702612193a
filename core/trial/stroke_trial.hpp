#pragma once

#include <array>
#include <vector>

#include "core/scene/scene_model.hpp"
#include "core/trial/reference_trial.hpp"

namespace hapticsim {

/** Where the proxy was in one period of a stroke, and how it touched. */
struct ProxySample {
  std::array<double, 3> rest_position_m{};  ///< the proxy's material point, grid frame, m
  bool in_contact = false;
  bool sliding = false;
};

struct StrokeTrialResult {
  TrialResult trial;               ///< forces on the user, as every trial records them
  std::vector<ProxySample> proxy;  ///< one per recorded sample
};

/**
 * A stroke (input.waveform = "stroke") on the full-resolution object: the tool moved by the
 * ContactTrajectory from the contact node's rest position, touching through a ProxyContact with
 * the scene's friction; the contact node is free like every other node (nothing is driven).
 *
 * Refused as predicted unstable (TrialOutcome::kPredictedUnstable) when solver.dt is past the
 * limit of the object with the contact spring on its lightest face node: 2 / √(ω_max² + k/m),
 * which TrialResult::stability.critical_dt_s then reports — unless `substep_to_stability`, as
 * TrialOptions asks of a reference: then each period takes the substeps that keep within 95 % of
 * that limit, the proxy touching at each (the tool on its path), as the regions' primary does.
 * A proxy that reaches the edge of the face ends the trial (kLeftSurface). `frames`: the whole
 * object at the start of the periods they ask for (hapticsim simulate --vtk).
 */
StrokeTrialResult RunStrokeTrial(const SceneModel& object, bool substep_to_stability = false,
                                 const TrialFrames& frames = {});

}  // namespace hapticsim
