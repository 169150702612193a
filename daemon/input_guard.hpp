#pragma once

#include <array>
#include <cstdint>
#include <string_view>

#include "core/scene/scene.hpp"

namespace hapticsim {

/** Why a device input was refused. */
enum class InputRejection : int {
  kAccepted = 0,
  kNonFinite,         ///< a coordinate is NaN or infinite
  kOutsideWorkspace,  ///< beyond the object's box grown by the workspace margin
  kJump,              ///< faster than max_speed since the last accepted input (no hand moves so)
  kOldSequence,       ///< seq not newer than the last accepted one (duplicate or reordered)
  kSeqOutOfRange,     ///< seq below 0 or above InputGuard::kMaxSeq
};
inline constexpr int kNumInputRejections = 6;
std::string_view InputRejectionName(InputRejection rejection);

/**
 * Checks device inputs before they reach the simulation (the I/O thread calls it for every
 * message). Sequence gaps are counted, not refused: a lost message is no reason to drop the
 * next one.
 */
class InputGuard {
 public:
  /** Silence after which the next input starts a new session (any seq, any position), s. */
  static constexpr double kNewSessionAfter_s = 0.5;
  /** The largest seq accepted: 2⁵³, up to which a double (the resampler's timeline) holds
   *  every integer; at 1 kHz, 285,000 years of device periods. */
  static constexpr std::int64_t kMaxSeq = std::int64_t{1} << 53;

  /** `object_extent_m`: the object's box, from 0 to it along each axis (ContactObject::extent_m).
   */
  InputGuard(const std::array<double, 3>& object_extent_m, double workspace_margin_m,
             double max_speed_m_per_s)
      : extent_m_(object_extent_m), margin_m_(workspace_margin_m), max_speed_(max_speed_m_per_s) {}

  InputRejection Check(std::int64_t seq, const std::array<double, 3>& position_m,
                       std::int64_t received_ns) noexcept;

  std::int64_t sequence_gaps() const { return gaps_; }
  /** Forget the last accepted input (after a reset or a long pause). */
  void Reset() { have_last_ = false; }

 private:
  std::array<double, 3> extent_m_;
  double margin_m_, max_speed_;
  bool have_last_ = false;
  std::int64_t last_seq_ = 0, last_ns_ = 0, gaps_ = 0;
  std::array<double, 3> last_position_{};
};

}  // namespace hapticsim
