#include "core/trial/reference_trial.hpp"

#include <cmath>

#include "core/error.hpp"
#include "core/fem/central_difference_integrator.hpp"
#include "core/scene/contact_trajectory.hpp"
#include "core/trial/stroke_trial.hpp"
#include "core/trial/trial_recorder.hpp"

namespace hapticsim {

ObjectState LatticeState(const ElasticModel& model, const Eigen::VectorXd& u) {
  const HexGrid& grid = model.grid();
  ObjectState state;
  state.lattice_nodes = {grid.nx(), grid.ny(), grid.nz()};
  state.displacement_m.resize(3 * state.num_points());
  for (int ix = 0; ix < grid.nx(); ++ix) {
    for (int iy = 0; iy < grid.ny(); ++iy) {
      for (int iz = 0; iz < grid.nz(); ++iz) {
        const int node = grid.Node(ix, iy, iz);
        for (int c = 0; c < 3; ++c)
          state.displacement_m[state.Index(ix, iy, iz) + c] = u[grid.Dof(node, c)];
      }
    }
  }
  return state;
}

std::string_view TrialOutcomeName(TrialOutcome outcome) {
  switch (outcome) {
    case TrialOutcome::kCompleted:
      return "completed";
    case TrialOutcome::kPredictedUnstable:
      return "predicted unstable";
    case TrialOutcome::kDivergedNonFinite:
      return "diverged: non-finite values";
    case TrialOutcome::kDivergedEnergy:
      return "diverged: energy growth";
    case TrialOutcome::kLeftSurface:
      return "stopped: the stroke left the face it slides on";
    case TrialOutcome::kDivergedContact:
      return "diverged: the proxy slid out of the primary region within one period";
  }
  return "unknown";
}

TrialResult RunReferenceTrial(const SceneModel& cube, const TrialOptions& options) {
  const Scene& scene = cube.scene();
  if (scene.input.waveform == Waveform::kStroke) {
    return RunStrokeTrial(cube, options.substep_to_stability, options.frames).trial;
  }
  const ElasticModel& model = cube.model();
  TrialResult result;
  result.stability = EstimateStability(model);
  const double dt = scene.solver.dt_s;
  if (!result.stability.IsStable(dt) && options.substep_to_stability) {
    result.substeps = static_cast<int>(std::ceil(dt / (0.95 * result.stability.critical_dt_s)));
  } else if (!result.stability.IsStable(dt) && !options.run_if_predicted_unstable) {
    result.outcome = TrialOutcome::kPredictedUnstable;
    return result;
  }
  const double h = dt / result.substeps;

  CentralDifferenceIntegrator integrator(model, h);
  const ContactTrajectory trajectory(scene.input, cube.contact_normal());
  const long steps = scene.num_steps();
  TrialRecorder recorder(trajectory, dt, steps, &result);
  // Period n goes from tₙ to tₙ₊₁; its first step yields the reaction at tₙ, so periods 0…N give
  // samples 0…N.
  std::array<double, 3> reaction_at_start{};
  for (long n = 0; n <= steps; ++n) {
    const double t = n * dt;
    if (options.frames.Due(n))
      options.frames.observe(t, LatticeState(model, integrator.displacement()));
    StepStatus status = StepStatus::kOk;
    for (int q = 1; q <= result.substeps && status == StepStatus::kOk; ++q) {
      status = integrator.Step(trajectory.DisplacementAt(t + q * h));
      if (q == 1) {
        for (int c = 0; c < 3; ++c) reaction_at_start[c] = integrator.driven_reaction()[c];
      }
    }
    if (status != StepStatus::kOk) {
      recorder.Stop(status == StepStatus::kNonFinite ? TrialOutcome::kDivergedNonFinite
                                                     : TrialOutcome::kDivergedEnergy);
      break;
    }
    if (!recorder.Record(n, reaction_at_start)) break;
  }
  result.wall_time_s = recorder.ElapsedS();
  return result;
}

}  // namespace hapticsim
