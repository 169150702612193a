#include "daemon/input_guard.hpp"

#include <cmath>

namespace hapticsim {

std::string_view InputRejectionName(InputRejection rejection) {
  switch (rejection) {
    case InputRejection::kAccepted:
      return "accepted";
    case InputRejection::kNonFinite:
      return "non-finite position";
    case InputRejection::kOutsideWorkspace:
      return "position outside the workspace";
    case InputRejection::kJump:
      return "jump faster than input.max_speed_m_per_s";
    case InputRejection::kOldSequence:
      return "seq not newer than the last accepted";
    case InputRejection::kSeqOutOfRange:
      return "seq outside 0 to 2^53 (input.seq counts device periods)";
  }
  return "unknown";
}

InputRejection InputGuard::Check(std::int64_t seq, const std::array<double, 3>& p,
                                 std::int64_t received_ns) noexcept {
  if (seq < 0 || seq > kMaxSeq) return InputRejection::kSeqOutOfRange;
  for (double x : p) {
    if (!std::isfinite(x)) return InputRejection::kNonFinite;
  }
  for (int c = 0; c < 3; ++c) {
    if (p[c] < -margin_m_ || p[c] > extent_m_[c] + margin_m_) {
      return InputRejection::kOutsideWorkspace;
    }
  }
  // A device silent for a while starts a new session: a restarted driver counts from 1 again and
  // its tool may be anywhere, so neither the old seq nor the old position applies.
  if (have_last_ && static_cast<double>(received_ns - last_ns_) * 1e-9 > kNewSessionAfter_s) {
    have_last_ = false;
  }
  if (have_last_) {
    if (seq <= last_seq_) return InputRejection::kOldSequence;
    // Time between arrivals, at least half a millisecond: arrival jitter must not turn a normal
    // step into an impossible speed.
    const double dt = std::max(5e-4, (received_ns - last_ns_) * 1e-9);
    const double dx =
        std::hypot(p[0] - last_position_[0], p[1] - last_position_[1], p[2] - last_position_[2]);
    if (dx > max_speed_ * dt) return InputRejection::kJump;
    if (seq > last_seq_ + 1) ++gaps_;
  }
  have_last_ = true;
  last_seq_ = seq;
  last_ns_ = received_ns;
  last_position_ = p;
  return InputRejection::kAccepted;
}

}  // namespace hapticsim
