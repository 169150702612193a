#pragma once

#include <array>

#include "core/scene/scene.hpp"

namespace hapticsim {

/**
 * The prescribed displacement of the contact node along its face's inward normal, m:
 *   press: s·(1 − cos 2πft)/2,   sine: s·sin 2πft,   both 0 for t < 0 (at rest before the trial).
 * Linear in the amplitude s by construction.
 */
class ContactTrajectory {
 public:
  /** `inward_normal`: the unit normal the node moves along (InwardNormal; +z on the front). */
  explicit ContactTrajectory(const InputSettings& input,
                             const std::array<double, 3>& inward_normal = {0.0, 0.0, 1.0})
      : input_(input), normal_(inward_normal) {}

  /** Displacement into the object at time t (s), m. */
  double DepthAt(double t_s) const;
  /** The node's displacement vector at time t (s): DepthAt(t) × the inward normal, m. */
  std::array<double, 3> DisplacementAt(double t_s) const {
    const double depth = DepthAt(t_s);
    return {depth * normal_[0], depth * normal_[1], depth * normal_[2]};
  }
  const std::array<double, 3>& inward_normal() const { return normal_; }

 private:
  InputSettings input_;
  std::array<double, 3> normal_;
};

}  // namespace hapticsim
