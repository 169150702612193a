// The device report's force steps between answers (ForceSteps): which pairs of answers each kind
// of step counts.
#include "device/force_steps.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "hapticsim/force_feedback_t.hpp"

namespace hapticsim::device {
namespace {

constexpr std::int32_t kContact = force_feedback_t::FLAG_IN_CONTACT;

// The daemon's answers in its periods, one after the other, into `steps`.
struct Answers {
  ForceSteps steps;
  std::int64_t period = 0;

  // An answer to inputs first_seq … seq with a force along z, in the daemon's next period.
  void Take(std::int64_t first_seq, std::int64_t seq, double fz, std::int32_t flags = kContact) {
    Answer a;
    a.period = period++;
    a.first_seq = first_seq;
    a.seq = seq;
    a.force_n = {0, 0, fz};
    a.flags = flags;
    steps.Take(a);
  }
};

TEST(ForceSteps, OnePeriodsStepIsBetweenAnswersThatEachTookTheNextInput) {
  Answers answers;
  answers.Take(1, 1, 0.0);
  answers.Take(2, 2, 0.05);  // the first answer has none before it: not one period's step
  answers.Take(3, 3, 0.09);  // one input each: 0.04 N in one period
  answers.Take(4, 6, 0.29);  // a late period caught up through three inputs: 0.2 N
  answers.Take(7, 7, 0.32);  // the answer before took three: not one period's
  answers.Take(8, 8, 0.38);  // 0.06 N in one period
  EXPECT_NEAR(answers.steps.one_period_n(), 0.06, 1e-15);
  EXPECT_NEAR(answers.steps.in_contact_n(), 0.2, 1e-15);
  EXPECT_NEAR(answers.steps.any_n(), 0.2, 1e-15);
}

// The device late: the daemon answers again with no new input (the same seq), carrying the tip
// on by itself; the input after brings the tip's motion of several periods in one answer.
TEST(ForceSteps, AnAnswerThatTookNoNewInputIsNotOnePeriodsStepNorIsTheOneAfterIt) {
  Answers answers;
  answers.Take(1, 1, 0.0);
  answers.Take(2, 2, 0.01);
  answers.Take(3, 3, 0.02);  // 0.01 N in one period
  answers.Take(3, 3, 0.04);  // no new input: 0.02 N
  answers.Take(3, 3, 0.06);
  answers.Take(4, 4, 0.21);  // the next input after the device's gap: 0.15 N
  answers.Take(5, 5, 0.22);
  EXPECT_NEAR(answers.steps.one_period_n(), 0.01, 1e-15);
  EXPECT_NEAR(answers.steps.in_contact_n(), 0.15, 1e-15);
}

// A lost answer or a non-finite force between two that each took one input: the step across it
// is not one period's.
TEST(ForceSteps, AStepAcrossALostAnswerOrANonFiniteForceIsNotOnePeriods) {
  Answers answers;
  answers.Take(1, 1, 0.0);
  answers.Take(2, 2, 0.01);
  answers.Take(3, 3, 0.02);
  ++answers.period;          // lost: an answer that took no new input
  answers.Take(4, 4, 0.12);  // 0.1 N over two periods
  answers.Take(5, 5, NAN);   // no step to or from a non-finite force
  answers.Take(6, 6, 0.30);
  answers.Take(7, 7, 0.31);  // 0.01 N in one period
  EXPECT_NEAR(answers.steps.one_period_n(), 0.01, 1e-15);
  EXPECT_NEAR(answers.steps.in_contact_n(), 0.1, 1e-15);
}

TEST(ForceSteps, StepsInContactLeaveOutLiftOffsAndStaleInput) {
  Answers answers;
  answers.Take(1, 1, 0.4);
  answers.Take(2, 2, 0.1, 0);  // lifted off: the release is a step, not one in contact
  answers.Take(3, 3, 0.0, kContact);
  answers.Take(4, 4, 0.3, kContact | force_feedback_t::FLAG_INPUT_STALE);
  answers.Take(5, 5, 0.32, kContact);
  answers.Take(6, 6, 0.35, kContact);
  EXPECT_NEAR(answers.steps.any_n(), 0.3, 1e-15);
  EXPECT_NEAR(answers.steps.in_contact_n(), 0.03, 1e-15);
  EXPECT_NEAR(answers.steps.one_period_n(), 0.03, 1e-15);
}

}  // namespace
}  // namespace hapticsim::device
