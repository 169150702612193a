#pragma once

#include "core/scene.hpp"

namespace hapticsim {

/**
 * The prescribed displacement of the contact node along the inward normal (+z), m:
 *   press: s·(1 − cos 2πft)/2,   sine: s·sin 2πft,   both 0 for t < 0 (at rest before the trial).
 * Linear in the amplitude s by construction.
 */
class ContactTrajectory {
 public:
  explicit ContactTrajectory(const InputSettings& input) : input_(input) {}

  /** Displacement into the object at time t (s), m. */
  double DepthAt(double t_s) const;

 private:
  InputSettings input_;
};

}  // namespace hapticsim
