#include "daemon/input_intake.hpp"

namespace hapticsim {

void InputIntake::Offer(std::int64_t seq, const std::array<double, 3>& position_m) {
  if (!owns_input_) {
    counters_.inputs_wrong_transport.fetch_add(1);  // the loop never sees it
    return;
  }
  counters_.inputs_received.fetch_add(1);
  const std::int64_t now = HapticLoop::NowNs();
  const InputRejection verdict = guard_.Check(seq, position_m, now);
  if (verdict == InputRejection::kAccepted) {
    last_accepted_ = {seq, now, position_m, false};
  } else {
    counters_.Reject(verdict);
    last_accepted_.latest_rejected = true;  // the primary flags it; the simulation keeps the last
  }
  loop_.OfferInput(last_accepted_);
}

}  // namespace hapticsim
