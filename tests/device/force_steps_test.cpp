// The device report's force steps between answers (ForceSteps): which pairs of answers each kind
// of step counts.
#include "device/force_steps.hpp"

#include <gtest/gtest.h>

#include "hapticsim/force_feedback_t.hpp"

namespace hapticsim::device {
namespace {

constexpr std::int32_t kContact = force_feedback_t::FLAG_IN_CONTACT;

// An answer to inputs first_seq … seq with a force along z.
Answer Of(std::int64_t first_seq, std::int64_t seq, double fz, std::int32_t flags = kContact) {
  Answer a;
  a.first_seq = first_seq;
  a.seq = seq;
  a.force_n = {0, 0, fz};
  a.flags = flags;
  return a;
}

TEST(ForceSteps, OnePeriodsStepIsBetweenAnswersThatEachTookTheNextInput) {
  ForceSteps steps;
  steps.Take(Of(1, 1, 0.0));
  steps.Take(Of(2, 2, 0.05));  // one input each: 0.05 N in one period
  steps.Take(Of(3, 5, 0.25));  // a late period caught up through three inputs: 0.2 N
  steps.Take(Of(6, 6, 0.28));  // the answer before took three: not one period's
  steps.Take(Of(7, 7, 0.36));  // 0.08 N in one period
  EXPECT_NEAR(steps.one_period_n(), 0.08, 1e-15);
  EXPECT_NEAR(steps.in_contact_n(), 0.2, 1e-15);
  EXPECT_NEAR(steps.any_n(), 0.2, 1e-15);
}

// The device late: the daemon answers again with no new input (the same seq), carrying the tip
// on by itself; the input after brings the tip's motion of several periods in one answer.
TEST(ForceSteps, AnAnswerThatTookNoNewInputIsNotOnePeriodsStepNorIsTheOneAfterIt) {
  ForceSteps steps;
  steps.Take(Of(1, 1, 0.0));
  steps.Take(Of(2, 2, 0.01));
  steps.Take(Of(2, 2, 0.03));  // no new input: 0.02 N
  steps.Take(Of(2, 2, 0.05));
  steps.Take(Of(3, 3, 0.20));  // the next input after the device's gap: 0.15 N
  steps.Take(Of(4, 4, 0.21));
  EXPECT_NEAR(steps.one_period_n(), 0.01, 1e-15);
  EXPECT_NEAR(steps.in_contact_n(), 0.15, 1e-15);
}

TEST(ForceSteps, StepsInContactLeaveOutLiftOffsAndStaleInput) {
  ForceSteps steps;
  steps.Take(Of(1, 1, 0.4));
  steps.Take(Of(2, 2, 0.1, 0));  // lifted off: the release is a step, not one in contact
  steps.Take(Of(3, 3, 0.0, kContact));
  steps.Take(Of(4, 4, 0.3, kContact | force_feedback_t::FLAG_INPUT_STALE));
  steps.Take(Of(5, 5, 0.32, kContact));
  EXPECT_NEAR(steps.any_n(), 0.3, 1e-15);
  EXPECT_NEAR(steps.in_contact_n(), 0.02, 1e-15);
  EXPECT_NEAR(steps.one_period_n(), 0.02, 1e-15);
}

}  // namespace
}  // namespace hapticsim::device
