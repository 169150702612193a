// The one record every trial keeps of its periods (TrialRecorder): what a sample is, the peak,
// and how a trial ends — the same for the reference, the regions in virtual time and on threads.
#include "core/trial/trial_recorder.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "core/trial/reference_trial.hpp"

namespace hapticsim {
namespace {

TEST(TrialRecorder, ASampleIsTheForceOnTheUserAtThePeriodsStartBesideTheContactsPlace) {
  InputSettings input;  // the paper's 1 cm press at 1 Hz
  const ContactTrajectory trajectory(input);
  TrialResult result;
  TrialRecorder recorder(trajectory, 1e-3, 1000, &result);
  EXPECT_GE(result.samples.capacity(), 1001u);
  ASSERT_TRUE(recorder.Record(0, {0, 0, 0.5}));
  ASSERT_TRUE(recorder.Record(1, {3, -4, 0}));
  ASSERT_TRUE(recorder.Record(2, {0, 0, 1}));
  ASSERT_EQ(result.samples.size(), 3u);
  EXPECT_EQ(result.steps, 3);
  EXPECT_DOUBLE_EQ(result.samples[1].t_s, 1e-3);
  EXPECT_EQ(result.samples[1].feedback_force_n, (std::array<double, 3>{-3, 4, -0}));
  EXPECT_EQ(result.samples[2].contact_displacement_m, trajectory.DisplacementAt(2e-3));
  EXPECT_DOUBLE_EQ(result.peak_force_n, 5.0);  // |(3, −4, 0)|
  EXPECT_DOUBLE_EQ(result.stopped_at_s, 2e-3);
  EXPECT_EQ(result.outcome, TrialOutcome::kCompleted);
}

TEST(TrialRecorder, ANonFiniteReactionEndsTheTrialUnrecorded) {
  const ContactTrajectory trajectory{InputSettings{}};
  TrialResult result;
  TrialRecorder recorder(trajectory, 1e-3, 10, &result);
  ASSERT_TRUE(recorder.Record(0, {0, 0, 1}));
  EXPECT_FALSE(recorder.Record(1, {0, std::numeric_limits<double>::quiet_NaN(), 1}));
  EXPECT_EQ(result.outcome, TrialOutcome::kDivergedNonFinite);
  EXPECT_EQ(result.samples.size(), 1u) << "a non-finite force is not a sample";
  EXPECT_EQ(result.steps, 1);
  EXPECT_DOUBLE_EQ(result.stopped_at_s, 0);
  EXPECT_TRUE(std::isfinite(result.peak_force_n));
  EXPECT_FALSE(recorder.Record(2, {0, 0, INFINITY}));
}

TEST(TrialRecorder, AStopSaysHowTheTrialEnded) {
  const ContactTrajectory trajectory{InputSettings{}};
  TrialResult result;
  TrialRecorder recorder(trajectory, 1e-3, 10, &result);
  recorder.Stop(TrialOutcome::kDivergedEnergy, /*runaway=*/true);
  EXPECT_TRUE(result.diverged());
  EXPECT_TRUE(result.runaway);
  EXPECT_TRUE(result.samples.empty());
  EXPECT_GE(recorder.ElapsedS(), 0);
}

}  // namespace
}  // namespace hapticsim
