#pragma once

#include <array>
#include <algorithm>
#include <chrono>
#include <cmath>

#include "core/scene/contact_trajectory.hpp"
#include "core/trial/reference_trial.hpp"

namespace hapticsim {

/**
 * What every trial does with its periods' answers, whoever steps them: the full-resolution
 * reference (RunReferenceTrial), the regions in virtual time (AsyncRegions::RunTrial, which the
 * error map and the stress test run) and the regions on real threads (RealTimeSchedule). Each
 * steps period n from tₙ to tₙ₊₁ its own way and hands over the reaction at tₙ; this makes it
 * the period's sample (the force on the user, −R, beside the prescribed contact displacement),
 * keeps the peak and how far the trial got, and ends it: a reaction that is not finite ends it
 * unrecorded, as does a divergence the stepper found (Stop).
 */
class TrialRecorder {
 public:
  /** Starts the trial's clock; `result` gets room for the periods 0 … steps. */
  TrialRecorder(const ContactTrajectory& trajectory, double dt_s, long steps, TrialResult* result)
      : trajectory_(trajectory), dt_s_(dt_s), result_(*result), start_(Clock::now()) {
    result_.samples.reserve(static_cast<size_t>(steps) + 1);
  }

  /** Period n's reaction at its start, N. False when the trial ends here (not finite). */
  bool Record(long n, const std::array<double, 3>& reaction_n) {
    const std::array<double, 3>& r = reaction_n;
    if (!std::isfinite(r[0] + r[1] + r[2])) {
      Stop(TrialOutcome::kDivergedNonFinite);
      return false;
    }
    const double t = n * dt_s_;
    ForceSample sample;
    sample.t_s = t;
    sample.contact_displacement_m = trajectory_.DisplacementAt(t);
    for (int c = 0; c < 3; ++c) sample.feedback_force_n[c] = -r[c];
    result_.peak_force_n =
        std::max(result_.peak_force_n, std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]));
    result_.samples.push_back(sample);
    result_.stopped_at_s = t;
    result_.steps = static_cast<long>(result_.samples.size());
    return true;
  }
  /** The stepper found the trial diverged before the period it was stepping was recorded. */
  void Stop(TrialOutcome outcome, bool runaway = false) {
    result_.outcome = outcome;
    result_.runaway = runaway;
  }
  /** The wall time since the recorder was made, s (the stepping loop's). */
  double ElapsedS() const {
    return std::chrono::duration<double>(Clock::now() - start_).count();
  }

 private:
  using Clock = std::chrono::steady_clock;
  const ContactTrajectory& trajectory_;
  double dt_s_;
  TrialResult& result_;
  Clock::time_point start_;
};

}  // namespace hapticsim
