#include "core/trial/stroke_trial.hpp"

#include <cmath>

#include "core/error.hpp"
#include "core/fem/region_integrator.hpp"
#include "core/fem/stability_estimate.hpp"
#include "core/scene/contact_trajectory.hpp"
#include "core/trial/proxy_contact.hpp"
#include "core/trial/trial_recorder.hpp"

namespace hapticsim {
namespace {

// Every DOF on the object but the held ones: the contact node is free in a stroke.
std::vector<int> OwnedDofs(const ElasticModel& model) {
  std::vector<bool> held(static_cast<std::size_t>(model.grid().num_dofs()), false);
  for (int dof : model.constraints().fixed_dofs) held[static_cast<std::size_t>(dof)] = true;
  std::vector<int> owned;
  for (int dof = 0; dof < model.grid().num_dofs(); ++dof) {
    if (model.dof_mass()[dof] > 0 && !held[static_cast<std::size_t>(dof)]) owned.push_back(dof);
  }
  return owned;
}

}  // namespace

StrokeTrialResult RunStrokeTrial(const SceneModel& object, bool substep_to_stability,
                                 const TrialFrames& frames) {
  const Scene& scene = object.scene();
  const ElasticModel& model = object.model();
  StrokeTrialResult out;
  TrialResult& result = out.trial;
  ProxyContact contact(model, object.contact_node(), object.contact_normal(), scene.contact);
  const auto stroke_axis = static_cast<std::size_t>(scene.input.stroke_axis);
  HAPTICSIM_THROW_UNLESS(object.contact_normal()[stroke_axis] == 0,
                         "input.stroke_direction = " +
                             GetSceneValue(scene, "input.stroke_direction") +
                             " points into the contact's face: a stroke moves along the face, "
                             "choose one of the other two axes");
  // The contact spring adds at most k/m to ω² (it is positive semi-definite, of norm ≤ k/m on
  // its lightest node): the object's limit with it.
  result.stability = EstimateStability(model);
  const double omega = result.stability.omega_max_rad_s;
  result.stability.critical_dt_s =
      2.0 / std::sqrt(omega * omega +
                      scene.contact.stiffness_n_per_m / contact.lightest_loaded_mass_kg());
  const double dt = scene.solver.dt_s;
  if (!result.stability.IsStable(dt) && substep_to_stability) {
    result.substeps = static_cast<int>(std::ceil(dt / (0.95 * result.stability.critical_dt_s)));
  } else if (!result.stability.IsStable(dt)) {
    result.outcome = TrialOutcome::kPredictedUnstable;
    return out;
  }
  const double h = dt / result.substeps;
  const std::vector<int>& fixed = model.constraints().fixed_dofs;
  RegionIntegrator integrator(model.stiffness(), model.dof_mass(), model.dof_damping(),
                              OwnedDofs(model), fixed, contact.loaded_dofs(), h);
  integrator.SetEnergyTerms(false);
  const std::vector<double> held_at_rest(fixed.size(), 0.0);
  const ContactTrajectory trajectory(scene.input, object.contact_normal());
  const long steps = scene.num_steps();
  TrialRecorder recorder(trajectory, dt, steps, &result);
  out.proxy.reserve(static_cast<std::size_t>(steps) + 1);
  // Each substep: one step, the proxy touching with the tool where hapticsimd has it
  // (ContactTrajectory::SubstepToolAt), the spring taken at the step's end (ProxyPush); the
  // period's sample is its first substep's force. False when the trial ends.
  const auto step_period = [&](long n) {
    if (frames.Due(n)) frames.observe(n * dt, LatticeState(model, integrator.u()));
    for (int q = 0; q < result.substeps; ++q) {
      std::array<double, 3> tool = contact.start_m();
      const std::array<double, 3> moved = trajectory.SubstepToolAt(n, q, result.substeps, dt);
      for (int c = 0; c < 3; ++c) tool[c] += moved[c];
      ProxyPush push(contact, tool);
      integrator.Step(held_at_rest, push);
      const ProxyContact::Result& touch = push.touch;
      if (touch.left_surface) {
        recorder.Stop(TrialOutcome::kLeftSurface);
        return false;
      }
      if (q == 0) {
        if (!recorder.Record(n, touch.force_on_object_n)) return false;
        out.proxy.push_back({contact.proxy_rest_m(), touch.in_contact, touch.sliding});
      }
      if (!std::isfinite(integrator.OwnedStateMaxAbs())) {
        recorder.Stop(TrialOutcome::kDivergedNonFinite);
        return false;
      }
    }
    return true;
  };
  for (long n = 0; n <= steps && step_period(n); ++n) {
  }
  result.wall_time_s = recorder.ElapsedS();
  return out;
}

}  // namespace hapticsim
