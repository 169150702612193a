#pragma once

#include <Eigen/Core>
#include <array>
#include <functional>
#include <string_view>
#include <vector>

#include "core/fem/elastic_model.hpp"
#include "core/fem/object_state.hpp"
#include "core/fem/stability_estimate.hpp"
#include "core/scene/scene_model.hpp"

namespace hapticsim {

/** How a run ended. */
enum class TrialOutcome {
  kCompleted,
  kPredictedUnstable,  ///< refused before the first step: dt ≥ the critical step
  kDivergedNonFinite,  ///< detected during the run: a non-finite value
  kDivergedEnergy,     ///< detected during the run: energy beyond the passivity budget
  kLeftSurface,        ///< a stroke's proxy reached the edge of the face it slides on
  /// detected during a stroke on the regions: the proxy slid out of the primary region within
  /// one period, farther than any tool moves in a millisecond (the contact diverging)
  kDivergedContact,
};

std::string_view TrialOutcomeName(TrialOutcome outcome);

/** One sample of the force time series. */
struct ForceSample {
  double t_s = 0;                                  ///< time, s
  std::array<double, 3> contact_displacement_m{};  ///< prescribed contact displacement, m
  std::array<double, 3> feedback_force_n{};        ///< force on the user, −R, N
};

struct TrialResult {
  TrialOutcome outcome = TrialOutcome::kCompleted;
  /** kDivergedEnergy by the runaway watch (AsyncRegions::Runaway): the state outgrew what the
   *  energy balance allows, long before it outgrew the passivity budget. */
  bool runaway = false;
  StabilityEstimate stability;
  std::vector<ForceSample> samples;  ///< t = 0, dt, …, duration (fewer if it diverged)
  long steps = 0;                    ///< periods of solver.dt simulated (= samples)
  int substeps = 1;                  ///< integrator steps per period
  double stopped_at_s = 0;           ///< time of the last completed step
  double peak_force_n = 0;           ///< max |feedback force| over the samples, N
  double wall_time_s = 0;            ///< compute time of the stepping loop, s

  bool diverged() const {
    return outcome == TrialOutcome::kDivergedNonFinite ||
           outcome == TrialOutcome::kDivergedEnergy || outcome == TrialOutcome::kDivergedContact;
  }
};

/**
 * Frames of a trial for looking at it offline (hapticsim simulate --vtk): the whole object's
 * displacement on the fine lattice (ObjectState, velocities left empty) at the start of every
 * `every_periods`-th period of solver.dt from period 0, with that period's time, s.
 */
struct TrialFrames {
  long every_periods = 0;  ///< 0: no frames
  std::function<void(double t_s, const ObjectState& state)> observe;
  bool Due(long period) const { return every_periods > 0 && period % every_periods == 0; }
};

/** A full-resolution displacement `u` (the model's DOFs) in the lattice's order, as frames take
 *  it (the grid's nodes are its points). */
ObjectState LatticeState(const ElasticModel& model, const Eigen::VectorXd& u);

struct TrialOptions {
  /** Run even when the prediction says dt is past the stability limit (to watch detection). */
  bool run_if_predicted_unstable = false;
  /**
   * The reference of an error comparison: when solver.dt is past the stability limit, take as
   * many equal substeps per dt as keep each at most 0.95 of the limit, and still report one
   * sample per dt. (The paper: "a sufficiently low time-step to maintain stability".)
   */
  bool substep_to_stability = false;
  TrialFrames frames;
};

/**
 * The full-resolution reference simulation of a scene: the whole cube at the finest mesh,
 * stepped by central difference over the trial, with the stability limit predicted before the
 * first step and divergence detected during the run.
 */
TrialResult RunReferenceTrial(const SceneModel& cube, const TrialOptions& options = {});

}  // namespace hapticsim
