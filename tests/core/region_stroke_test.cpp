// A tool stroked across the surface through the sliding proxy on the asynchronous regions
// (RunRegionStroke): the primary region follows the proxy, rebuilt around the node nearest it and
// started from the object's motion. Checked against what the contact model promises and what
// does not depend on the regions: once sliding, the lateral force is the kinetic friction times
// the normal force (within 5 %); without friction there is no lateral force; the force never
// steps by more than 0.1 N from one period to the next, at the primary's moves included; the
// stroke follows the full-resolution reference's (RunStrokeTrial); and a held press settles on
// the contact spring in series with the object's stiffness from the static solve.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "core/error.hpp"
#include "core/fem/static_solver.hpp"
#include "core/regions/region_stroke_trial.hpp"
#include "core/scene/scene_model.hpp"
#include "core/trial/force_error.hpp"

namespace hapticsim {
namespace {

Scene Stroke(double static_mu, double kinetic_mu, double length_m = 0.03) {
  Scene scene;
  scene.input.waveform = Waveform::kStroke;
  scene.input.amplitude_m = 0.005;  // 5 mm deep
  scene.input.stroke_length_m = length_m;
  scene.contact.static_friction = static_mu;
  scene.contact.kinetic_friction = kinetic_mu;
  scene.adaptivity.primary_size = 3;
  return scene;
}

double Normal(const ForceSample& s) { return -s.feedback_force_n[2]; }
double Lateral(const ForceSample& s) {
  return std::hypot(s.feedback_force_n[0], s.feedback_force_n[1]);
}

double LargestStep(const std::vector<ForceSample>& samples) {
  double largest = 0;
  for (std::size_t i = 1; i < samples.size(); ++i) {
    const auto& a = samples[i - 1].feedback_force_n;
    const auto& b = samples[i].feedback_force_n;
    largest = std::max(largest, std::hypot(b[0] - a[0], b[1] - a[1], b[2] - a[2]));
  }
  return largest;
}

// The reference stroke on the full-resolution cube: the same scene without regions.
StrokeTrialResult Reference(Scene scene) {
  scene.adaptivity.primary_size = 0;
  return RunStrokeTrial(SceneModel(scene));
}

// 80 mm from the middle of the front face (20.8 mm spacing): the proxy crosses four nodes, so
// the primary moves four times.
constexpr double kLongStroke = 0.08;

TEST(RegionStroke, ThePrimaryFollowsTheProxyAcrossTheFace) {
  const RegionStrokeResult run = RunRegionStroke(Stroke(0.5, 0.4, kLongStroke));
  ASSERT_EQ(run.stroke.trial.outcome, TrialOutcome::kCompleted);
  ASSERT_EQ(run.stroke.proxy.size(), run.stroke.trial.samples.size());
  ASSERT_GE(run.moves.size(), 3u);
  // Each move is one node along the stroke, to the node the proxy was nearest then.
  const double h = 0.25 / 12;
  for (std::size_t i = 0; i < run.moves.size(); ++i) {
    const RegionStrokeResult::Move& move = run.moves[i];
    EXPECT_EQ(move.centre[0], 7 + static_cast<int>(i));
    EXPECT_EQ(move.centre[1], 6);
    EXPECT_EQ(move.centre[2], 0);
    const double proxy_x =
        run.stroke.proxy[static_cast<std::size_t>(move.period)].rest_position_m[0];
    EXPECT_NEAR(proxy_x / h, move.centre[0], 0.5 + 1e-9) << "move " << i;
  }
}

TEST(RegionStroke, OnceSlidingTheLateralForceIsTheKineticFrictionTimesTheNormal) {
  const RegionStrokeResult run = RunRegionStroke(Stroke(0.5, 0.4, kLongStroke));
  ASSERT_EQ(run.stroke.trial.outcome, TrialOutcome::kCompleted);
  int sliding = 0;
  double worst = 0;
  const auto& samples = run.stroke.trial.samples;
  for (std::size_t i = 1; i < samples.size(); ++i) {
    if (!run.stroke.proxy[i].sliding) continue;
    ++sliding;
    worst = std::max(worst, Lateral(samples[i]) / Normal(samples[i]));
    EXPECT_GE(Lateral(samples[i]), 0.95 * 0.4 * Normal(samples[i])) << "t = " << samples[i].t_s;
  }
  std::printf("sliding in %d of %zu periods: lateral at most %.4f × normal\n", sliding,
              samples.size(), worst);
  EXPECT_GT(sliding, 300);
  EXPECT_LE(worst, 0.4 * 1.05);
}

TEST(RegionStroke, WithoutFrictionThereIsNoLateralForce) {
  const RegionStrokeResult run = RunRegionStroke(Stroke(0.0, 0.0, kLongStroke));
  ASSERT_EQ(run.stroke.trial.outcome, TrialOutcome::kCompleted);
  double largest = 0, largest_normal = 0;
  for (const ForceSample& s : run.stroke.trial.samples) {
    largest = std::max(largest, Lateral(s));
    largest_normal = std::max(largest_normal, Normal(s));
  }
  std::printf(
      "frictionless on the regions: largest lateral %.5f N, largest normal %.4f N, "
      "%zu moves\n",
      largest, largest_normal, run.moves.size());
  EXPECT_GE(run.moves.size(), 3u);
  EXPECT_LT(largest, 0.05);
  EXPECT_GT(largest_normal, 0.3);  // the tool did press
}

// The change of the force vector from period i to i + 1, N.
double StepAt(const std::vector<ForceSample>& samples, std::size_t i) {
  const auto& a = samples[i].feedback_force_n;
  const auto& b = samples[i + 1].feedback_force_n;
  return std::hypot(b[0] - a[0], b[1] - a[1], b[2] - a[2]);
}

TEST(RegionStroke, TheForceDoesNotStepWhereThePrimaryMoves) {
  for (const double mu : {0.0, 0.4}) {
    const Scene scene = Stroke(mu + 0.1, mu, kLongStroke);
    const RegionStrokeResult run = RunRegionStroke(scene);
    const StrokeTrialResult reference = Reference(scene);
    ASSERT_EQ(run.stroke.trial.outcome, TrialOutcome::kCompleted);
    const auto& samples = run.stroke.trial.samples;
    // Across each move (the period it ended and the next) the force changes as the reference's,
    // which never moves anything, changes over the same period.
    double at_moves = 0, beyond_reference = 0;
    for (const RegionStrokeResult::Move& move : run.moves) {
      const auto i = static_cast<std::size_t>(move.period);
      at_moves = std::max(at_moves, StepAt(samples, i));
      beyond_reference =
          std::max(beyond_reference, StepAt(samples, i) - StepAt(reference.trial.samples, i));
    }
    // … and no more than it does anywhere else in the stroke, where nothing moves.
    double elsewhere = 0;
    for (std::size_t i = 0; i + 1 < samples.size(); ++i) {
      elsewhere = std::max(elsewhere, StepAt(samples, i) - StepAt(reference.trial.samples, i));
    }
    const double largest = LargestStep(samples);
    std::printf(
        "mu_k %.1f: largest step %.4f N (reference stroke %.4f N); across the %zu moves "
        "%.4f N, at most %.5f N more than the reference's there (%.5f N anywhere)\n",
        mu, largest, LargestStep(reference.trial.samples), run.moves.size(), at_moves,
        beyond_reference, elsewhere);
    EXPECT_LT(largest, 0.1) << "mu_k " << mu;
    EXPECT_LT(beyond_reference, 0.005) << "mu_k " << mu;
  }
}

TEST(RegionStroke, FollowsTheFullResolutionStroke) {
  for (const double mu : {0.0, 0.4}) {
    const Scene scene = Stroke(mu + 0.1, mu, kLongStroke);
    const RegionStrokeResult run = RunRegionStroke(scene);
    const StrokeTrialResult reference = Reference(scene);
    ASSERT_EQ(run.stroke.trial.outcome, TrialOutcome::kCompleted);
    ASSERT_EQ(reference.trial.outcome, TrialOutcome::kCompleted);
    const ForceError e = CompareForces(run.stroke.trial.samples, reference.trial.samples);
    std::printf(
        "mu_k %.1f against the reference: relative L2 %.3f %%, largest %.3f %% of its peak\n", mu,
        e.l2_percent, e.max_magnitude_percent);
    EXPECT_LT(e.l2_percent, 3.0) << "mu_k " << mu;
  }
}

TEST(RegionStroke, AHeldPressSettlesOnTheSpringInSeriesWithTheObject) {
  Scene scene = Stroke(0.5, 0.4, 0.0);  // press 5 mm and hold
  scene.input.periods = 4;              // 1 s of press, 3 s of hold: the damping settles it
  const RegionStrokeResult run = RunRegionStroke(scene);
  ASSERT_EQ(run.stroke.trial.outcome, TrialOutcome::kCompleted);
  EXPECT_TRUE(run.moves.empty());
  const SceneModel object([&] {
    Scene full = scene;
    full.adaptivity.primary_size = 0;
    return full;
  }());
  const std::array<double, 3> unit = {0, 0, 1e-3};
  const double k_object = SolveStatic(object.model(), unit).driven_reaction[2] / 1e-3;
  const double k_spring = scene.contact.stiffness_n_per_m;
  const double expected = 0.005 * k_object * k_spring / (k_object + k_spring);
  const double settled = Normal(run.stroke.trial.samples.back());
  std::printf("held press on the regions: %.5f N against %.5f N\n", settled, expected);
  // The coarse secondary is stiffer than the full-resolution object: within the error map's
  // few per cent.
  EXPECT_NEAR(settled / expected, 1.0, 0.03);
}

// A block as soft as the palpation phantom's tissue (10 kPa) on a lattice finer than the press is
// deep: 4 cm, 2.5 mm voxels, pressed 3 mm and stroked 20 mm without friction.
Scene SoftFineStroke(double radius_m) {
  Scene scene = Stroke(0.0, 0.0, 0.02);
  scene.mesh.nodes = 17;
  scene.mesh.edge_m = 0.04;
  scene.material.youngs_modulus_pa = 10000;
  scene.material.poisson_ratio = 0.45;
  scene.input.amplitude_m = 0.003;
  scene.contact.radius_m = radius_m;
  return scene;
}

// The stroke on the regions against the full-resolution one (its steps 50 µs, under the
// object's limit with the spring: 77 µs), at the regions' sample times.
struct FineStrokeCheck {
  RegionStrokeResult run;
  double lateral_n = 0, normal_n = 0, largest_step_n = 0, l2_percent = 0;
  double reference_lateral_n = 0;
};
FineStrokeCheck StrokeAgainstTheFullResolution(const Scene& scene) {
  FineStrokeCheck check{RunRegionStroke(scene)};
  Scene full = scene;
  full.solver.dt_s = 5e-5;
  const StrokeTrialResult reference = Reference(full);
  const std::vector<ForceSample>& samples = check.run.stroke.trial.samples;
  std::vector<ForceSample> matched;
  for (std::size_t i = 0; i < samples.size() && 20 * i < reference.trial.samples.size(); ++i)
    matched.push_back(reference.trial.samples[20 * i]);
  for (const ForceSample& s : samples) {
    check.lateral_n = std::max(check.lateral_n, Lateral(s));
    check.normal_n = std::max(check.normal_n, Normal(s));
  }
  for (const ForceSample& s : reference.trial.samples)
    check.reference_lateral_n = std::max(check.reference_lateral_n, Lateral(s));
  check.largest_step_n = LargestStep(samples);
  const std::vector<ForceSample> compared(samples.begin(),
                                          samples.begin() + static_cast<long>(matched.size()));
  check.l2_percent = CompareForces(compared, matched).l2_percent;
  std::printf(
      "soft fine block, tip radius %.4f m: %s after %zu samples, %zu moves, largest lateral "
      "%.5f N, normal %.4f N, largest step %.4f N; against the full-resolution stroke (largest "
      "lateral %.5f N) relative L2 %.2f %%\n",
      scene.contact.radius_m, std::string(TrialOutcomeName(check.run.stroke.trial.outcome)).c_str(),
      samples.size(), check.run.moves.size(), check.lateral_n, check.normal_n, check.largest_step_n,
      check.reference_lateral_n, check.l2_percent);
  return check;
}

TEST(RegionStroke, OnALatticeFinerThanThePressIsDeepAWideTipSlidesWhereOneCellRunsAway) {
  // A tip on one cell's nodes dimples the surface under the proxy, and the proxy, reading the
  // surface from the same nodes, slides over its own dimple and runs away, on the regions and on
  // the full-resolution object alike (measured: the reference 3.5 N lateral on a press of
  // 0.06 N, frictionless; the regions 0.08 N, the stroke leaving its face early). With the
  // spring taken at each step's start the light nodes also rang under it and the regions'
  // stroke was stopped as diverged; taken at the step's end (ProxyPush) it is not, but the
  // geometry still runs away.
  const FineStrokeCheck cell = StrokeAgainstTheFullResolution(SoftFineStroke(0.0));
  EXPECT_TRUE(cell.run.stroke.trial.diverged() || cell.lateral_n > 0.05 ||
              cell.largest_step_n > 0.1);
  // A tip of 5 mm (two spacings) spreads the push and reads the surface over 16 nodes.
  const FineStrokeCheck wide = StrokeAgainstTheFullResolution(SoftFineStroke(0.005));
  ASSERT_EQ(wide.run.stroke.trial.outcome, TrialOutcome::kCompleted);
  EXPECT_GE(wide.run.moves.size(), 5u);
  EXPECT_LT(wide.lateral_n, 0.05);
  EXPECT_GT(wide.normal_n, 0.03);
  EXPECT_LT(wide.largest_step_n, 0.1);
  EXPECT_LT(wide.l2_percent, 5.0);
}

TEST(RegionStroke, AWideTipNeedsAPrimaryThatReachesIt) {
  Scene scene = SoftFineStroke(0.005);  // two spacings: the primary must reach three nodes
  scene.adaptivity.primary_size = 2;
  try {
    RunRegionStroke(scene);
    FAIL() << "a primary of two nodes was accepted for a 5 mm tip on 2.5 mm voxels";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("adaptivity.primary_size >= 3"), std::string::npos)
        << e.what();
  }
}

// A tip of one and a half spacings touches nodes up to two from a proxy that has slid up to ¾
// of a node from the primary's centre: a primary of two nodes is refused, of three it strokes.
TEST(RegionStroke, ATipOfOneAndAHalfSpacingsNeedsAPrimaryOfThreeNodes) {
  Scene scene = Stroke(0.5, 0.4, kLongStroke);
  scene.contact.radius_m = 1.5 * 0.25 / 12;
  scene.adaptivity.primary_size = 2;
  EXPECT_THROW(RunRegionStroke(scene), Error);
  scene.adaptivity.primary_size = 3;
  const RegionStrokeResult run = RunRegionStroke(scene);
  EXPECT_EQ(run.stroke.trial.outcome, TrialOutcome::kCompleted)
      << TrialOutcomeName(run.stroke.trial.outcome);
  EXPECT_GE(run.moves.size(), 3u);
}

TEST(RegionStroke, ThePrimaryMustReachTwoNodesFromTheProxy) {
  Scene scene = Stroke(0.5, 0.4);
  scene.adaptivity.primary_size = 1;
  try {
    RunRegionStroke(scene);
    FAIL() << "a primary of one node was accepted for a stroke";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("adaptivity.primary_size >= 2"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace hapticsim
