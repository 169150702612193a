#pragma once

#include <array>
#include <cstdint>

#include "daemon/haptic_loop.hpp"
#include "daemon/input_counters.hpp"
#include "daemon/input_guard.hpp"

namespace hapticsim {

/**
 * Where a device input enters, whatever carried it (LCM or shared memory): counted, checked by
 * an InputGuard, and handed to the primary thread — the newest accepted input, marked when a
 * newer one was refused (the simulation keeps the last accepted one). I/O thread only.
 */
class InputIntake {
 public:
  InputIntake(double workspace_margin_m, double max_speed_m_per_s, HapticLoop& loop,
              InputCounters& counters, bool owns_input)
      : guard_(loop.contact_object().extent_m(), workspace_margin_m, max_speed_m_per_s),
        loop_(loop),
        counters_(counters),
        owns_input_(owns_input) {}

  void Offer(std::int64_t seq, const std::array<double, 3>& position_m);
  /** A new driver: its seq and positions are not checked against the previous one's. */
  void Reset() {
    guard_.Reset();
    last_accepted_ = DeviceSample{};
  }

 private:
  InputGuard guard_;
  HapticLoop& loop_;
  InputCounters& counters_;
  bool owns_input_;
  DeviceSample last_accepted_;
};

}  // namespace hapticsim
