#pragma once

#include <algorithm>
#include <array>

#include "core/scene/scene.hpp"

namespace hapticsim {

/**
 * The prescribed displacement of the contact node along its face's inward normal, m:
 *   press: s·(1 − cos 2πft)/2,   sine: s·sin 2πft,   both 0 for t < 0 (at rest before the trial).
 * Linear in the amplitude s by construction.
 *
 * A stroke moves the tool, not a node: s deep by half a cosine over the first quarter of the
 * trial (input.periods / f), then input.stroke_length along input.stroke_direction over the rest,
 * as L·(x − sin 2πx / 2π), x from 0 to 1: at rest at both ends, no acceleration jump.
 */
class ContactTrajectory {
 public:
  /** `inward_normal`: the unit normal the node moves along (InwardNormal; +z on the front). */
  explicit ContactTrajectory(const InputSettings& input,
                             const std::array<double, 3>& inward_normal = {0.0, 0.0, 1.0})
      : input_(input), normal_(inward_normal) {}

  /** Displacement into the object at time t (s), m. */
  double DepthAt(double t_s) const;
  /** How far a stroke has moved along the surface at time t (s), m (0 for the others). */
  double LateralAt(double t_s) const;
  /** The displacement vector at time t (s): DepthAt(t) × the inward normal, plus a stroke's
   *  LateralAt(t) along its direction, m. */
  std::array<double, 3> DisplacementAt(double t_s) const;
  const std::array<double, 3>& inward_normal() const { return normal_; }

  /**
   * Where a stroke's tool is in substep q (0 … substeps − 1) of period n (period dt_s): as
   * hapticsimd moves it, which has one device sample a period (SlidingContact::StepPeriod), from
   * the last period's tip to this one's in equal parts, the last substep exactly at n · dt.
   */
  std::array<double, 3> SubstepToolAt(long n, int q, int substeps, double dt_s) const {
    const double behind = 1.0 - static_cast<double>(q + 1) / substeps;
    return DisplacementAt(std::max(0.0, (static_cast<double>(n) - behind) * dt_s));
  }

 private:
  // The share of a stroke's trial gone at time t (s): 0 … 1.
  double StrokePhase(double t_s) const;

  InputSettings input_;
  std::array<double, 3> normal_;
};

}  // namespace hapticsim
