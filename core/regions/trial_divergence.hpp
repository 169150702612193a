#pragma once
// How a trial on the regions ends early: the checks every one makes after each period, whoever
// steps it (AsyncRegions::RunTrial, RunRegionStroke).

#include <cmath>
#include <optional>

#include "core/regions/async_regions.hpp"
#include "core/trial/reference_trial.hpp"

namespace hapticsim {

/** The outcome that ends a trial early, as TrialRecorder::Stop takes it. */
struct TrialStop {
  TrialOutcome outcome = TrialOutcome::kDivergedEnergy;
  bool runaway = false;
};

/**
 * After a period: the state's energy `energy_j` not finite (kDivergedNonFinite), or above
 * AsyncRegions::kEnergyGrowthFactor × `allowed_j` — the energy the trial started with plus the
 * contact's work — (kDivergedEnergy), or the runaway watch held over `balance` (kDivergedEnergy,
 * runaway): what the daemon watches for, with the same numbers, so a trial the daemon would have
 * taken off these regions is not a sample of them. `runaway_periods` is the caller's count
 * (AsyncRegions::RunawayHeld). Nothing: the trial goes on.
 */
inline std::optional<TrialStop> DivergedAfterPeriod(
    const AsyncRegions& regions, const AsyncRegions::PublishedBalanceView& balance, double energy_j,
    double allowed_j, int* runaway_periods) noexcept {
  if (!std::isfinite(energy_j)) return TrialStop{TrialOutcome::kDivergedNonFinite, false};
  if (energy_j > AsyncRegions::kEnergyGrowthFactor * allowed_j && energy_j > 0) {
    return TrialStop{TrialOutcome::kDivergedEnergy, false};
  }
  if (regions.RunawayHeld(balance, runaway_periods)) {
    return TrialStop{TrialOutcome::kDivergedEnergy, true};
  }
  return std::nullopt;
}

}  // namespace hapticsim
