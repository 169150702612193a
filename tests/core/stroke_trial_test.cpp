// A tool stroked across the surface through the sliding (god-object) contact, on the
// full-resolution cube (RunStrokeTrial), checked against what the contact model promises and what
// does not depend on it: once sliding, the tangential force is the kinetic friction times the
// normal force (within 5 %); without friction there is no lateral force; the force never steps
// by more than 0.1 N from one period to the next while the proxy moves; with friction too high
// to break away nothing slides; and a press held still settles on the static answer of the
// contact spring in series with the object's own stiffness (the static solve, independent of the
// proxy).
#include "core/trial/stroke_trial.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/error.hpp"
#include "core/fem/static_solver.hpp"
#include "core/scene/contact_trajectory.hpp"
#include "core/trial/force_error.hpp"
#include "core/trial/proxy_contact.hpp"

namespace hapticsim {
namespace {

Scene Stroke(double static_mu, double kinetic_mu) {
  Scene scene;
  scene.input.waveform = Waveform::kStroke;
  scene.input.amplitude_m = 0.005;       // 5 mm deep
  scene.input.stroke_length_m = 0.03;    // 30 mm along +x
  scene.contact.static_friction = static_mu;
  scene.contact.kinetic_friction = kinetic_mu;
  return scene;
}

// The force on the user along the press (pushing out: positive) and across it.
double Normal(const ForceSample& s) { return -s.feedback_force_n[2]; }
double Lateral(const ForceSample& s) { return std::hypot(s.feedback_force_n[0], s.feedback_force_n[1]); }

TEST(StrokeTrial, OnceSlidingTheLateralForceIsTheKineticFrictionTimesTheNormal) {
  const StrokeTrialResult run = RunStrokeTrial(SceneModel(Stroke(0.5, 0.4)));
  ASSERT_EQ(run.trial.outcome, TrialOutcome::kCompleted);
  ASSERT_EQ(run.proxy.size(), run.trial.samples.size());
  int sliding = 0;
  double worst = 0;
  for (std::size_t i = 1; i < run.proxy.size(); ++i) {
    // A sample is rendered after its period's proxy update: its force is the one that slid.
    if (!run.proxy[i].sliding) continue;
    ++sliding;
    const ForceSample& s = run.trial.samples[i];
    worst = std::max(worst, Lateral(s) / Normal(s));
    EXPECT_LE(Lateral(s), 1.05 * 0.4 * Normal(s)) << "t = " << s.t_s;
    // … and no less: a sliding proxy holds the pull at μ_k times the push.
    EXPECT_GE(Lateral(s), 0.95 * 0.4 * Normal(s)) << "t = " << s.t_s;
  }
  std::printf("sliding in %d of %zu periods; largest lateral/normal while sliding %.4f\n",
              sliding, run.proxy.size(), worst);
  EXPECT_GT(sliding, 300);  // most of the 750 ms stroke
  // The proxy went most of the way with the tool: 30 mm less the spring's stretch.
  const double travelled = run.proxy.back().rest_position_m[0] - run.proxy.front().rest_position_m[0];
  EXPECT_GT(travelled, 0.025);
  EXPECT_LE(travelled, 0.03);
}

TEST(StrokeTrial, WithoutFrictionThereIsNoLateralForce) {
  const StrokeTrialResult run = RunStrokeTrial(SceneModel(Stroke(0.0, 0.0)));
  ASSERT_EQ(run.trial.outcome, TrialOutcome::kCompleted);
  double largest = 0, largest_normal = 0;
  for (const ForceSample& s : run.trial.samples) {
    largest = std::max(largest, Lateral(s));
    largest_normal = std::max(largest_normal, Normal(s));
  }
  std::printf("frictionless: largest lateral %.5f N, largest normal %.4f N\n", largest,
              largest_normal);
  EXPECT_LT(largest, 0.05);
  EXPECT_GT(largest_normal, 0.3);  // the tool did press
}

TEST(StrokeTrial, TheForceNeverStepsByMoreThanATenthOfANewtonWhileTheProxyMoves) {
  for (const double mu : {0.0, 0.4}) {
    const StrokeTrialResult run = RunStrokeTrial(SceneModel(Stroke(mu + 0.1, mu)));
    ASSERT_EQ(run.trial.outcome, TrialOutcome::kCompleted);
    double largest = 0;
    for (std::size_t i = 1; i < run.trial.samples.size(); ++i) {
      const auto& a = run.trial.samples[i - 1].feedback_force_n;
      const auto& b = run.trial.samples[i].feedback_force_n;
      largest = std::max(largest, std::hypot(b[0] - a[0], b[1] - a[1], b[2] - a[2]));
    }
    std::printf("mu_k %.1f: largest step between periods %.4f N\n", mu, largest);
    EXPECT_LT(largest, 0.1) << "mu_k " << mu;
  }
}

TEST(StrokeTrial, FrictionTooHighToBreakAwaySticksAndPullsBack) {
  const StrokeTrialResult run = RunStrokeTrial(SceneModel(Stroke(10.0, 10.0)));
  ASSERT_EQ(run.trial.outcome, TrialOutcome::kCompleted);
  for (const ProxySample& p : run.proxy) EXPECT_FALSE(p.sliding);
  EXPECT_EQ(run.proxy.back().rest_position_m, run.proxy[300].rest_position_m);
  // The surface is dragged along: it pulls back across the stroke, against it (−x).
  EXPECT_LT(run.trial.samples.back().feedback_force_n[0], -0.5);
}

TEST(StrokeTrial, AHeldPressSettlesOnTheSpringInSeriesWithTheObject) {
  Scene scene = Stroke(0.5, 0.4);
  scene.input.stroke_length_m = 0;  // press 5 mm and hold
  scene.input.periods = 4;          // 1 s of press, 3 s of hold: the damping (10/s) settles it
  const SceneModel object(scene);
  const StrokeTrialResult run = RunStrokeTrial(object);
  ASSERT_EQ(run.trial.outcome, TrialOutcome::kCompleted);
  // The object's own stiffness at the contact node, from the static solve.
  const std::array<double, 3> unit = {0, 0, 1e-3};
  const double k_object = SolveStatic(object.model(), unit).driven_reaction[2] / 1e-3;
  const double k_spring = scene.contact.stiffness_n_per_m;
  const double expected = 0.005 * k_object * k_spring / (k_object + k_spring);
  const double settled = Normal(run.trial.samples.back());
  std::printf("held press: %.5f N against %.5f N (object %.2f N/m, spring %.0f N/m)\n", settled,
              expected, k_object, k_spring);
  EXPECT_NEAR(settled / expected, 1.0, 0.01);
}

TEST(StrokeTrial, AContactSpringTooStiffForTheStepIsRefusedAsUnstable) {
  Scene scene = Stroke(0.5, 0.4);
  scene.contact.stiffness_n_per_m = 1e6;
  const StrokeTrialResult run = RunStrokeTrial(SceneModel(scene));
  EXPECT_EQ(run.trial.outcome, TrialOutcome::kPredictedUnstable);
  EXPECT_LT(run.trial.stability.critical_dt_s, scene.solver.dt_s);
  EXPECT_TRUE(run.trial.samples.empty());
}

TEST(StrokeTrial, AStrokeIntoTheFaceIsRefusedSayingWhichWaysItCanGo) {
  Scene scene = Stroke(0.5, 0.4);
  SetSceneValue(&scene, "input.stroke_direction", "-z");
  try {
    RunStrokeTrial(SceneModel(scene));
    ADD_FAILURE() << "a stroke along the face's normal ran";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find("points into the contact's face"), std::string::npos);
  }
}

// As a reference for the regions (simulate --compare-reference): a period past the limit with
// the spring is taken in substeps, the proxy touching at each, and gives what a run at a fine
// step gives. A 4 cm block of 2.5 mm voxels, 3 mm deep, a 5 mm tip, 20 mm with friction.
TEST(StrokeTrial, APeriodPastTheLimitIsSubsteppedWhenAReferenceAsksAndMatchesAFineStep) {
  Scene scene = Stroke(0.5, 0.4);
  scene.mesh.nodes = 17;
  scene.mesh.edge_m = 0.04;
  scene.input.amplitude_m = 0.003;
  scene.input.stroke_length_m = 0.02;
  scene.contact.radius_m = 0.005;
  const StrokeTrialResult refused = RunStrokeTrial(SceneModel(scene));  // 1 ms: past 77 µs
  EXPECT_EQ(refused.trial.outcome, TrialOutcome::kPredictedUnstable);
  const StrokeTrialResult substepped = RunStrokeTrial(SceneModel(scene), true);
  ASSERT_EQ(substepped.trial.outcome, TrialOutcome::kCompleted);
  EXPECT_EQ(substepped.trial.substeps,
            static_cast<int>(std::ceil(1e-3 / (0.95 * substepped.trial.stability.critical_dt_s))));
  scene.solver.dt_s = 2.5e-5;
  const StrokeTrialResult fine = RunStrokeTrial(SceneModel(scene));
  ASSERT_EQ(fine.trial.outcome, TrialOutcome::kCompleted);
  std::vector<ForceSample> matched;
  for (std::size_t i = 0; i < substepped.trial.samples.size(); ++i)
    matched.push_back(fine.trial.samples[40 * i]);
  const ForceError e = CompareForces(substepped.trial.samples, matched);
  std::printf("%d substeps of a 1 ms period against 25 µs steps: relative L2 %.3f %%\n",
              substepped.trial.substeps, e.l2_percent);
  EXPECT_LT(e.l2_percent, 2.0);
}

// The tip's patch: its loads add up to the spring's force (the weights sum to one), a tip centred
// on a node pushes the nodes around it symmetrically, and a tip narrower than a cell is the cell's
// bilinear patch, to the bit. A still press, no friction in play: the first contact period.
TEST(ProxyContact, ATipsLoadsSumToItsForceSymmetricallyAndANarrowTipIsTheCells) {
  Scene scene = Stroke(0.5, 0.4);
  scene.mesh.nodes = 9;
  const SceneModel object(scene);
  const ElasticModel& model = object.model();
  const double h = model.grid().spacing();
  Eigen::VectorXd u = Eigen::VectorXd::Zero(model.grid().num_dofs());
  auto loads_of = [&](double radius_m, const std::array<double, 3>& tool) {
    ContactSettings contact = scene.contact;
    contact.radius_m = radius_m;
    ProxyContact proxy(model, object.contact_node(), object.contact_normal(), contact);
    std::vector<double> loads(proxy.loaded_dofs().size(), 0.0);
    const std::vector<double> compliance(loads.size(), 1e-6);  // m/N: the push is k·d/(1 + k·C)
    const ProxyContact::Result touch = proxy.Update(tool, u, compliance, loads);
    EXPECT_TRUE(touch.in_contact);
    std::array<double, 3> sum{};
    for (std::size_t i = 0; i < loads.size(); ++i) sum[i % 3] += loads[i];
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(sum[c], touch.force_on_object_n[c], 1e-12);
    return loads;
  };
  const ProxyContact narrow(model, object.contact_node(), object.contact_normal(), scene.contact);
  const std::array<double, 3> start = narrow.start_m();
  const std::vector<int>& dofs = narrow.loaded_dofs();  // every tip loads the face's nodes so
  const std::array<double, 3> pressed = {start[0], start[1], start[2] + 0.002};
  // Centred on the node: 2.5 spacings reach 2 nodes each way, 25 nodes, mirror-symmetric.
  const std::vector<double> wide = loads_of(2.5 * h, pressed);
  int pushed = 0;
  for (std::size_t i = 2; i < wide.size(); i += 3) pushed += wide[i] > 0 ? 1 : 0;
  EXPECT_EQ(pushed, 25);
  const LatticeIndex c = model.grid().NodeIndices(object.contact_node());
  const auto z_load = [&](int dx, int dy) {
    const int node = model.grid().Node(c[0] + dx, c[1] + dy, c[2]);
    const auto at = std::find(dofs.begin(), dofs.end(), model.grid().Dof(node, 2));
    return wide[static_cast<std::size_t>(at - dofs.begin())];
  };
  EXPECT_DOUBLE_EQ(z_load(1, 2), z_load(-1, -2));
  EXPECT_DOUBLE_EQ(z_load(2, 1), z_load(-2, 1));
  EXPECT_GT(z_load(0, 0), z_load(1, 0));
  // Off the node, a tip of 0.9 spacings is the cell's bilinear patch: equal to the bit.
  const std::array<double, 3> off = {start[0] + 0.3 * h, start[1] + 0.6 * h, start[2] + 0.002};
  EXPECT_EQ(loads_of(0.9 * h, off), loads_of(0.0, off));
}

// A tool that goes past the face's rim leaves the surface the proxy can render: nothing is pushed
// in that update, but the last push's nodes and weights are kept, so that a caller fading that
// push out (SlidingContact's release) spreads it where it was pushed, summing to the push.
TEST(ProxyContact, OffTheFaceTheLastPushsSpreadIsKeptForAPushFadingOut) {
  Scene scene = Stroke(0.5, 0.4);
  scene.mesh.nodes = 9;
  const SceneModel object(scene);
  const ElasticModel& model = object.model();
  const Eigen::VectorXd u = Eigen::VectorXd::Zero(model.grid().num_dofs());
  ProxyContact proxy(model, object.contact_node(), object.contact_normal(), scene.contact);
  std::vector<double> loads(proxy.loaded_dofs().size(), 0.0), pushed(loads.size(), 0.0);
  const std::vector<double> compliance(loads.size(), 1e-6);
  const std::array<double, 3> start = proxy.start_m();
  ASSERT_TRUE(
      proxy.Update({start[0], start[1], start[2] + 0.002}, u, compliance, pushed).in_contact);
  const ProxyContact::Result off =
      proxy.Update({start[0] + 1.0, start[1], start[2] + 0.002}, u, compliance, loads);
  ASSERT_TRUE(off.left_surface);
  EXPECT_TRUE(std::all_of(loads.begin(), loads.end(), [](double l) { return l == 0; }));
  proxy.SpreadLoads({0.0, 0.0, 0.5}, loads);
  double sum = 0;
  for (std::size_t i = 2; i < loads.size(); i += 3) {
    sum += loads[i];
    EXPECT_EQ(loads[i] > 0, pushed[i] > 0) << "another node than the last push's, DOF " << i;
  }
  EXPECT_NEAR(sum, 0.5, 1e-12);
}

// hapticsimd has one tool position a period and moves the primary's substeps from the last
// period's to this one's in equal parts, the last exactly there (SlidingContact::StepPeriod); the
// offline strokes, the reference's and the regions', take the tool there too. (They took substep
// q at n + q/S periods: (1 − 1/S) of a period ahead of the daemon. Against hapticsimd on a
// stroke of 4 substeps a period, 2.04 % → 1.83 % relative L2; the rest is the order the regions
// are stepped in, docs/regions.md.)
TEST(StrokeTrial, TheSubstepsTakeTheToolFromTheLastPeriodsTipToThisOnes) {
  InputSettings input;
  input.waveform = Waveform::kStroke;
  input.amplitude_m = 0.005;
  input.stroke_length_m = 0.03;
  const ContactTrajectory path(input);
  const double dt = 1e-3;
  for (const long n : {1L, 200L, 600L}) {
    for (int q = 0; q < 4; ++q) {
      const std::array<double, 3> at = path.SubstepToolAt(n, q, 4, dt);
      const std::array<double, 3> expected = path.DisplacementAt((n - 1 + (q + 1) / 4.0) * dt);
      for (int c = 0; c < 3; ++c) EXPECT_DOUBLE_EQ(at[c], expected[c]) << n << " " << q;
    }
    EXPECT_EQ(path.SubstepToolAt(n, 3, 4, dt), path.DisplacementAt(n * dt)) << "the last substep";
    EXPECT_EQ(path.SubstepToolAt(n, 0, 1, dt), path.DisplacementAt(n * dt)) << "one substep";
  }
  // Before the first period the tool is where the trial starts.
  EXPECT_EQ(path.SubstepToolAt(0, 0, 4, dt), path.DisplacementAt(0.0));
}

TEST(StrokeTrial, KineticFrictionAboveStaticIsRefused) {
  Scene scene = Stroke(0.3, 0.4);
  EXPECT_THROW(ValidateScene(scene), Error);
  // On the regions, the primary must reach two nodes from the proxy it follows.
  scene = Stroke(0.5, 0.4);
  scene.adaptivity.primary_size = 1;
  EXPECT_THROW(ValidateScene(scene), Error);
  scene.adaptivity.primary_size = 2;
  EXPECT_NO_THROW(ValidateScene(scene));
}

}  // namespace
}  // namespace hapticsim
