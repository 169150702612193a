#pragma once

#include <vector>

#include "core/trial/reference_trial.hpp"

namespace hapticsim {

/**
 * How far an adaptive run's force is from the reference's, sample by sample (same times):
 *
 * - l2_percent: relative L2 error of the force vector over the trial,
 *   100·√(Σ|F − F_ref|²) / √(Σ|F_ref|²);
 * - max_magnitude_percent: worst | |F| − |F_ref| | as a percentage of the reference's peak |F_ref|
 *   (the human just-noticeable difference is about 7 %);
 * - max_direction_deg: worst angle between F and F_ref over the samples where |F_ref| is at least
 *   kDirectionThreshold of its peak (direction is meaningless near zero force; humans notice
 *   18–32°).
 */
struct ForceError {
  static constexpr double kDirectionThreshold = 0.1;
  double l2_percent = 0;
  double max_magnitude_percent = 0;
  double max_direction_deg = 0;
  double reference_peak_n = 0;
  int samples = 0;
};

/** @throws Error when the two series do not have the same sample times. */
ForceError CompareForces(const std::vector<ForceSample>& adaptive,
                         const std::vector<ForceSample>& reference);

}  // namespace hapticsim
