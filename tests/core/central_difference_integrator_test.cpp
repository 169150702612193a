#include "core/fem/central_difference_integrator.hpp"

#include <gtest/gtest.h>

#include "core/scene/contact_trajectory.hpp"
#include "core/scene/scene_model.hpp"
#include "core/trial/reference_trial.hpp"
#include "core/fem/stability_estimate.hpp"
#include "core/fem/static_solver.hpp"
#include "tests/support/random_field.hpp"

namespace hapticsim {
namespace {

Scene SmallCube(int nodes) {
  Scene scene;
  scene.mesh.nodes = nodes;
  return scene;
}

// A random displacement on the free DOFs (zero where prescribed), so every mode is excited.
Eigen::VectorXd RandomFreeState(const ElasticModel& model, unsigned seed) {
  return testing::RandomField(model.grid().num_dofs(), seed, 1e-4).cwiseProduct(model.free_mask());
}

// Central difference conserves E = ½(u⁺ − u)ᵀM(u⁺ − u)/dt² + ½uᵀK u⁺ exactly for an undamped,
// unforced system (multiply the update by (u⁺ − u⁻)/2 and telescope).
double ShadowEnergy(const ElasticModel& model, const Eigen::VectorXd& u,
                    const Eigen::VectorXd& u_next, double dt) {
  Eigen::VectorXd k_next(u.size());
  model.stiffness().Apply(u_next, k_next);
  const Eigen::VectorXd du = u_next - u;
  return 0.5 * du.cwiseProduct(model.dof_mass()).dot(du) / (dt * dt) + 0.5 * u.dot(k_next);
}

TEST(CentralDifference, UndampedFreeVibrationConservesEnergyOver10kSteps) {
  Scene scene = SmallCube(7);
  scene.material.damping_per_s = 0;
  const SceneModel cube(scene);
  const double dt = 0.9 * EstimateStability(cube.model()).critical_dt_s;
  CentralDifferenceIntegrator dut(cube.model(), dt);
  const Eigen::VectorXd u0 = RandomFreeState(cube.model(), 3);
  dut.SetState(u0, u0);
  const std::array<double, 3> held{0, 0, 0};

  double first = 0, worst_drift = 0, max_energy = 0, min_energy = INFINITY;
  for (int n = 0; n < 10000; ++n) {
    const Eigen::VectorXd before = dut.displacement();
    ASSERT_EQ(dut.Step(held), StepStatus::kOk) << "step " << n;
    const double shadow = ShadowEnergy(cube.model(), before, dut.displacement(), dt);
    if (n == 0) first = shadow;
    worst_drift = std::max(worst_drift, std::abs(shadow - first));
    max_energy = std::max(max_energy, dut.energy());
    min_energy = std::min(min_energy, dut.energy());
  }
  EXPECT_LT(worst_drift, 1e-10 * first);
  // The positive-definite energy the divergence check uses stays within a bounded band.
  EXPECT_LT(max_energy, 20 * first);
}

TEST(CentralDifference, StableJustBelowThePredictedLimitDivergentJustAbove) {
  for (double damping : {0.0, 40.0}) {
    Scene scene = SmallCube(7);
    scene.material.damping_per_s = damping;
    const SceneModel cube(scene);
    const double critical = EstimateStability(cube.model()).critical_dt_s;
    const std::array<double, 3> held{0, 0, 0};
    const Eigen::VectorXd u0 = RandomFreeState(cube.model(), 5);

    CentralDifferenceIntegrator below(cube.model(), 0.99 * critical);
    below.SetState(u0, u0);
    const double start_energy = [&] {
      below.Step(held);
      return below.energy();
    }();
    double max_energy = 0;
    for (int n = 0; n < 20000; ++n) {
      ASSERT_EQ(below.Step(held), StepStatus::kOk) << "d = " << damping << ", step " << n;
      max_energy = std::max(max_energy, below.energy());
    }
    EXPECT_LT(max_energy, 100 * start_energy) << "d = " << damping;

    CentralDifferenceIntegrator above(cube.model(), 1.01 * critical);
    above.SetState(u0, u0);
    int detected_at = -1;
    for (int n = 0; n < 2000 && detected_at < 0; ++n) {
      if (above.Step(held) != StepStatus::kOk) detected_at = n;
    }
    EXPECT_GE(detected_at, 0) << "d = " << damping << ": divergence at 1.01×dt_crit not detected";
  }
}

TEST(CentralDifference, RunPastTheLimitFromRestIsDetected) {
  // From rest only round-off seeds the unstable mode; detection must still come within a
  // bounded number of steps, long before the trial ends.
  Scene scene = SmallCube(9);
  const SceneModel probe(scene);
  scene.solver.dt_s = 1.02 * EstimateStability(probe.model()).critical_dt_s;
  TrialOptions options;
  options.run_if_predicted_unstable = true;
  const TrialResult result = RunReferenceTrial(SceneModel(scene), options);
  EXPECT_TRUE(result.diverged());
  EXPECT_LT(result.steps, 600);

  const TrialResult refused = RunReferenceTrial(SceneModel(scene));
  EXPECT_EQ(refused.outcome, TrialOutcome::kPredictedUnstable);
  EXPECT_EQ(refused.steps, 0);
}

TEST(CentralDifference, ReferenceSubstepsPastTheLimitEqualAFinerTimeStep) {
  // A stiff scene whose 1 ms step is past the limit: the reference of an error comparison takes
  // two 0.5 ms substeps per sample, which must be exactly the run at dt = 0.5 ms, sampled every
  // other step.
  Scene stiff = SmallCube(9);
  stiff.material.youngs_modulus_pa = 60e3;
  stiff.material.poisson_ratio = 0.49;
  stiff.material.density_kg_m3 = 800;
  TrialOptions options;
  options.substep_to_stability = true;
  const TrialResult substepped = RunReferenceTrial(SceneModel(stiff), options);
  ASSERT_EQ(substepped.outcome, TrialOutcome::kCompleted);
  ASSERT_EQ(substepped.substeps, 2);
  Scene fine = stiff;
  fine.solver.dt_s = 0.5e-3;
  const TrialResult direct = RunReferenceTrial(SceneModel(fine));
  ASSERT_EQ(direct.outcome, TrialOutcome::kCompleted);
  ASSERT_EQ(direct.samples.size(), 2 * substepped.samples.size() - 1);
  // Equal up to the rounding of the sample times (n·dt + h against (2n + 1)·h).
  double worst = 0;
  for (size_t i = 0; i < substepped.samples.size(); ++i) {
    worst = std::max(worst, std::abs(substepped.samples[i].feedback_force_n[2] -
                                     direct.samples[2 * i].feedback_force_n[2]));
  }
  EXPECT_LT(worst, 1e-12 * direct.peak_force_n);
  // Without the option the same scene is refused, as before.
  EXPECT_EQ(RunReferenceTrial(SceneModel(stiff)).outcome, TrialOutcome::kPredictedUnstable);
}

TEST(CentralDifference, ResponseIsExactlyLinearInTheInputAmplitude) {
  Scene small = SmallCube(7);
  small.input.amplitude_m = 0.005;
  Scene large = small;
  large.input.amplitude_m = 0.015;
  const TrialResult a = RunReferenceTrial(SceneModel(small));
  const TrialResult b = RunReferenceTrial(SceneModel(large));
  ASSERT_EQ(a.samples.size(), b.samples.size());
  double worst = 0;
  for (size_t i = 0; i < a.samples.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      worst = std::max(worst, std::abs(b.samples[i].feedback_force_n[c] -
                                       3.0 * a.samples[i].feedback_force_n[c]));
    }
  }
  EXPECT_LT(worst, 1e-12 * b.peak_force_n);
}

TEST(CentralDifference, SlowUndampedPressConvergesToTheStaticSolve) {
  // A press at 0.05 Hz is an order of magnitude below the cube's lowest modes (~0.4 Hz), so at
  // full depth the dynamic reaction is the static one up to (f/f₀)² ≈ 1 %; the smooth press
  // excites the modes far less than that.
  Scene scene = SmallCube(9);
  scene.material.damping_per_s = 0;
  scene.input.frequency_hz = 0.05;
  scene.input.periods = 0.5;  // end at full depth
  const TrialResult dynamic = RunReferenceTrial(SceneModel(scene));
  ASSERT_EQ(dynamic.outcome, TrialOutcome::kCompleted);
  const std::array<double, 3> depth{0, 0, scene.input.amplitude_m};
  const double static_reaction =
      SolveStatic(SceneModel(scene).model(), depth, 1e-12).driven_reaction[2];
  const double dynamic_reaction = -dynamic.samples.back().feedback_force_n[2];
  EXPECT_NEAR(dynamic_reaction, static_reaction, 0.005 * static_reaction);
}

TEST(CentralDifference, ReactionOpposesThePress) {
  const TrialResult result = RunReferenceTrial(SceneModel(SmallCube(7)));
  ASSERT_EQ(result.outcome, TrialOutcome::kCompleted);
  // Half way through the press the contact is at full depth: the user is pushed back out (−z).
  const ForceSample& mid = result.samples[result.samples.size() / 2];
  EXPECT_LT(mid.feedback_force_n[2], 0.0);
}

}  // namespace
}  // namespace hapticsim
