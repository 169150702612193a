#include "device/force_steps.hpp"

#include <algorithm>
#include <cmath>

#include "hapticsim/force_feedback_t.hpp"

namespace hapticsim::device {

namespace {

bool Finite(const Answer& a) { return std::isfinite(a.force_n[0] + a.force_n[1] + a.force_n[2]); }

}  // namespace

void ForceSteps::Take(const Answer& a) {
  // An answer that took no new input repeats the newest seq it answered before; one after a lost
  // answer (a gap in the daemon's periods) is two periods' step, not one.
  const bool took_one = previous_ && a.first_seq == a.seq && a.seq == previous_->seq + 1 &&
                        a.period == previous_->period + 1;
  if (previous_ && Finite(a) && Finite(*previous_)) {
    const double step =
        std::hypot(a.force_n[0] - previous_->force_n[0], a.force_n[1] - previous_->force_n[1],
                   a.force_n[2] - previous_->force_n[2]);
    any_n_ = std::max(any_n_, step);
    const bool contact = (a.flags & force_feedback_t::FLAG_IN_CONTACT) &&
                         (previous_->flags & force_feedback_t::FLAG_IN_CONTACT) &&
                         !(a.flags & force_feedback_t::FLAG_INPUT_STALE);
    if (contact) {
      in_contact_n_ = std::max(in_contact_n_, step);
      if (took_one && previous_took_one_) one_period_n_ = std::max(one_period_n_, step);
    }
  }
  previous_ = a;
  previous_took_one_ = took_one;
}

}  // namespace hapticsim::device
