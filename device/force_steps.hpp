#pragma once

#include <optional>

#include "device/device_link.hpp"

namespace hapticsim::device {

/**
 * The largest force steps between consecutive answers, as the device's report keeps them:
 *
 * - any: between any two answers, in contact or not (a lift-off's release included);
 * - in contact: both answers in contact, the newer not flagged stale input;
 * - one period: the same, and each of the two answers took exactly one new input, the one after
 *   the input the answer before it took, in the daemon's next period. Neither a daemon period
 *   that caught up through several inputs nor one that answered again with no new input (the
 *   device late: the daemon carried the tip on by itself) is one period's step: after either,
 *   the tip's motion of several periods arrives in one answer. (So a session's first two
 *   answers are never one: the first has none before it.)
 *
 * Steps are force vectors' differences, N; none is taken to or from a non-finite force.
 */
class ForceSteps {
 public:
  void Take(const Answer& answer);

  double any_n() const { return any_n_; }
  double in_contact_n() const { return in_contact_n_; }
  double one_period_n() const { return one_period_n_; }

 private:
  std::optional<Answer> previous_;
  bool previous_took_one_ = false;  // the answer before took one new input, the next
  double any_n_ = 0, in_contact_n_ = 0, one_period_n_ = 0;
};

}  // namespace hapticsim::device
