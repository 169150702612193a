#include "core/scene/contact_trajectory.hpp"

#include <cmath>
#include <numbers>

namespace hapticsim {

double ContactTrajectory::DepthAt(double t_s) const {
  if (t_s < 0) return 0.0;
  const double phase = 2.0 * std::numbers::pi * input_.frequency_hz * t_s;
  switch (input_.waveform) {
    case Waveform::kPress:
      return input_.amplitude_m * (1.0 - std::cos(phase)) / 2.0;
    case Waveform::kSine:
      return input_.amplitude_m * std::sin(phase);
  }
  return 0.0;
}

}  // namespace hapticsim
