#include "core/scene/contact_trajectory.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace hapticsim {
namespace {

// A stroke presses in during its first quarter and moves along the surface in the rest.
constexpr double kStrokePressShare = 0.25;

}  // namespace

double ContactTrajectory::DepthAt(double t_s) const {
  if (t_s < 0) return 0.0;
  const double phase = 2.0 * std::numbers::pi * input_.frequency_hz * t_s;
  switch (input_.waveform) {
    case Waveform::kPress:
      return input_.amplitude_m * (1.0 - std::cos(phase)) / 2.0;
    case Waveform::kSine:
      return input_.amplitude_m * std::sin(phase);
    case Waveform::kStroke: {
      // Half a cosine over the press: no velocity jump at either end.
      const double share = std::min(1.0, StrokePhase(t_s) / kStrokePressShare);
      return input_.amplitude_m * (1.0 - std::cos(std::numbers::pi * share)) / 2.0;
    }
  }
  return 0.0;
}

double ContactTrajectory::LateralAt(double t_s) const {
  if (input_.waveform != Waveform::kStroke || t_s < 0) return 0.0;
  const double x =
      std::clamp((StrokePhase(t_s) - kStrokePressShare) / (1.0 - kStrokePressShare), 0.0, 1.0);
  // x − sin(2πx)/2π: starts and stops at rest, fastest halfway.
  return input_.stroke_length_m * (x - std::sin(2.0 * std::numbers::pi * x) /
                                           (2.0 * std::numbers::pi));
}

std::array<double, 3> ContactTrajectory::DisplacementAt(double t_s) const {
  const double depth = DepthAt(t_s);
  std::array<double, 3> d = {depth * normal_[0], depth * normal_[1], depth * normal_[2]};
  if (input_.waveform == Waveform::kStroke) {
    d[static_cast<std::size_t>(input_.stroke_axis)] += input_.stroke_sign * LateralAt(t_s);
  }
  return d;
}

double ContactTrajectory::StrokePhase(double t_s) const {
  return t_s * input_.frequency_hz / input_.periods;
}

}  // namespace hapticsim
