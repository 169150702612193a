// A trial on the virtual-time schedule (AsyncRegions::RunTrial): the secondaries stepped as far as
// the primary's coming step needs, then the primary, period after period, with the same
// divergence checks as the reference (RunReferenceTrial).
#include <algorithm>
#include <cmath>

#include "core/error.hpp"
#include "core/regions/async_regions.hpp"
#include "core/regions/async_regions_region.hpp"
#include "core/regions/trial_divergence.hpp"
#include "core/scene/contact_trajectory.hpp"
#include "core/trial/trial_recorder.hpp"

namespace hapticsim {

TrialResult AsyncRegions::RunTrial() { return RunTrial(partition_.scene().input); }

TrialResult AsyncRegions::RunTrial(const InputSettings& input) {
  Reset();
  return RunTrialFromCurrentState(input);
}

TrialResult AsyncRegions::RunTrialFromRandomState(const InputSettings& input, unsigned seed) {
  SetRandomState(seed);
  return RunTrialFromCurrentState(input);
}

TrialResult AsyncRegions::RunTrial(const TrialFrames& frames) {
  Reset();
  return RunTrialFromCurrentState(partition_.scene().input, frames);
}

TrialResult AsyncRegions::RunTrialFromCurrentState(const InputSettings& input,
                                                   const TrialFrames& frames) {
  HAPTICSIM_THROW_UNLESS(!partition_.proxy_contact(),
                         "a stroke on the regions runs through RunRegionStroke");
  TrialResult result;
  result.stability = regions_[kPrimaryRegion]->schedule.alone;
  const ContactTrajectory trajectory(input, partition_.contact_normal());
  const std::array<double, 3>& normal = trajectory.inward_normal();
  const double dt = 1.0 / regions_[kPrimaryRegion]->schedule.rate_hz;
  // As Scene::num_steps(), so a trial of the scene's own input matches the reference's length.
  const long steps =
      std::lround(input.periods / input.frequency_hz / partition_.scene().solver.dt_s);
  TrialRecorder recorder(trajectory, dt, steps, &result);
  const double budget = Energy();  // 0 from rest
  double work = 0;
  int runaway_periods = 0;  // in a row (kRunawayPeriods)
  Region& primary = *regions_[kPrimaryRegion];
  const int substeps = primary.schedule.substeps;
  const double h = dt / substeps;
  for (long n = 0; n <= steps; ++n) {
    const double t = n * dt;
    if (frames.Due(n)) frames.observe(t, CaptureState());
    std::array<double, 3> r{};
    for (int q = 1; q <= substeps; ++q) {
      AdvanceSecondariesForPrimaryStep();
      const double depth_next = trajectory.DepthAt(t + q * h);
      const std::array<double, 3> rq = StepPrimary(trajectory.DisplacementAt(t + q * h));
      if (q == 1) r = rq;
      const double reaction_along = rq[0] * normal[0] + rq[1] * normal[1] + rq[2] * normal[2];
      const double increment =
          reaction_along * (depth_next - trajectory.DepthAt(t + (q - 2) * h)) / 2.0;
      if (increment > 0) work += increment;
    }
    // The state's energy is bounded by the same passivity budget. With the controllers on, each
    // region published it before its last step (their pass computes it anyway; a second pass
    // was 3.9 % of a paper-grid shard's CPU under perf); with them off, the kinetic part alone, no
    // extra K·u.
    const PublishedBalanceView balance = PublishedBalance();
    const double energy =
        control_ != InterfaceControl::kOff ? balance.state_energy_j : KineticEnergy();
    if (!std::isfinite(r[0] + r[1] + r[2])) {
      recorder.Stop(TrialOutcome::kDivergedNonFinite);
      break;
    }
    if (const auto stop =
            DivergedAfterPeriod(*this, balance, energy, budget + work, &runaway_periods)) {
      recorder.Stop(stop->outcome, stop->runaway);
      break;
    }
    recorder.Record(n, r);
  }
  result.wall_time_s = recorder.ElapsedS();
  return result;
}

}  // namespace hapticsim
