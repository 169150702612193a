#include "core/trial/force_error.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/error.hpp"

namespace hapticsim {
namespace {

double Norm(const std::array<double, 3>& f) {
  return std::sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
}

}  // namespace

ForceError CompareForces(const std::vector<ForceSample>& adaptive,
                         const std::vector<ForceSample>& reference) {
  HAPTICSIM_THROW_UNLESS(adaptive.size() == reference.size(),
                         "the adaptive and reference runs have different numbers of samples (" +
                             std::to_string(adaptive.size()) + " vs " +
                             std::to_string(reference.size()) + ")");
  ForceError error;
  error.samples = static_cast<int>(reference.size());
  for (const ForceSample& s : reference)
    error.reference_peak_n = std::max(error.reference_peak_n, Norm(s.feedback_force_n));
  double difference2 = 0, reference2 = 0;
  for (size_t i = 0; i < reference.size(); ++i) {
    const auto& a = adaptive[i].feedback_force_n;
    const auto& r = reference[i].feedback_force_n;
    HAPTICSIM_THROW_UNLESS(std::abs(adaptive[i].t_s - reference[i].t_s) < 1e-9,
                           "the adaptive and reference runs sample different times");
    for (int c = 0; c < 3; ++c) {
      difference2 += (a[c] - r[c]) * (a[c] - r[c]);
      reference2 += r[c] * r[c];
    }
    const double na = Norm(a), nr = Norm(r);
    if (error.reference_peak_n > 0) {
      error.max_magnitude_percent =
          std::max(error.max_magnitude_percent, 100.0 * std::abs(na - nr) / error.reference_peak_n);
    }
    if (nr >= ForceError::kDirectionThreshold * error.reference_peak_n && nr > 0 && na > 0) {
      const double cosine =
          std::clamp((a[0] * r[0] + a[1] * r[1] + a[2] * r[2]) / (na * nr), -1.0, 1.0);
      error.max_direction_deg =
          std::max(error.max_direction_deg, std::acos(cosine) * 180.0 / std::numbers::pi);
    }
  }
  error.l2_percent = reference2 > 0 ? 100.0 * std::sqrt(difference2 / reference2) : 0.0;
  return error;
}

}  // namespace hapticsim
