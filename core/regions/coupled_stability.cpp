// The spectral analyser of the coupled regions (an analysis, not what the daemon runs): the
// period map's spectral radius by power iteration in the orbit norm (EstimateCoupledStability),
// the state norms it measures growth in, and the free-decay energies. docs/regions.md, "Stability
// of the coupled system".
#include <algorithm>
#include <cmath>
#include <random>

#include "core/error.hpp"
#include "core/regions/async_regions.hpp"
#include "core/regions/async_regions_region.hpp"

namespace hapticsim {

RegionIndex AsyncRegions::LargestStateRegion() const {
  RegionIndex largest = kPrimaryRegion;
  double largest_size = -1;
  for (int r = 0; r < num_regions(); ++r) {
    const double size = regions_[r]->integrator->OwnedStateNormSquared();
    if (!std::isfinite(size)) return r;
    if (size > largest_size) largest = r, largest_size = size;
  }
  return largest;
}

double AsyncRegions::StateNorm() const {
  double sum = 0;
  for (const auto& region : regions_) sum += region->integrator->OwnedStateNormSquared();
  return std::sqrt(sum);
}

double AsyncRegions::OrbitNorm() noexcept {
  double twice = 0;
  const Eigen::VectorXd& m = partition_.dof_mass();
  for (auto& region : regions_) {
    const Eigen::VectorXd& ku = region->integrator->Forces();  // the next step needs it anyway
    const Eigen::VectorXd& u = region->integrator->u();
    const Eigen::VectorXd& up = region->integrator->u_previous();
    const double h = region->integrator->substep();
    for (int i : region->dofs->owned) {
      twice += m[i] * (u[i] - up[i]) * (u[i] - up[i]) / (h * h) + up[i] * ku[i];
    }
    for (int i : region->dofs->outer_interface) twice += up[i] * ku[i];
  }
  if (!std::isfinite(twice)) return twice;  // grown past doubles: for the caller to see
  return std::sqrt(std::max(0.0, 0.5 * twice));
}

void AsyncRegions::ScaleAll(double factor) {
  // Energies scale with the square of the state: so scaled, the interface controllers act on the
  // scaled state as they would have on the original, and the period map stays homogeneous. The
  // running sums the neighbours exchange are rebased first (the part already counted on the
  // other side subtracted from both): renormalised every period by the power iteration, they
  // would otherwise outgrow each step's work by 10¹⁶ within a few hundred periods and absorb it.
  // (That leaves Energies' totals meaningless until the next Reset, which the iteration ends on.)
  for (int a = 1; a < num_regions(); ++a) {
    Region& outer = *regions_[a];
    Region& inner = *regions_[a - 1];
    inner.outer_gamma_work -= outer.inner_work_seen;
    inner.outward_taken -= outer.inner_taken_seen;
    outer.inner_work_seen = outer.inner_taken_seen = 0;
  }
  const double squared = factor * factor;
  state_energy_at_reset_j_ *= squared;
  for (auto& region : regions_) {
    for (double* energy :
         {&region->input_work, &region->damping_dissipated, &region->outer_gamma_work,
          &region->outward_taken, &region->inner_gamma_load_work, &region->inward_taken,
          &region->excess, &region->unmet, &region->inner_work_seen, &region->inner_taken_seen,
          &region->port_refused, &region->inward_allowance_peak, &region->outward_allowance_peak,
          &region->energy_peak, &region->lockstep_load_peak}) {
      *energy *= squared;
    }
    for (std::atomic<double>* published :
         {&region->energy_published, &region->state_energy_published}) {
      published->store(squared * published->load(std::memory_order_relaxed),
                       std::memory_order_relaxed);
    }
    PublishEnergyAccount(*region);
    region->integrator->ScaleState(factor);
    if (region->inward) region->inward->ScaleAll(factor);
    if (region->outward) region->outward->ScaleAll(factor);
  }
}

CoupledStability AsyncRegions::EstimateCoupledStability(int burn_in_periods, int window_periods,
                                                        int max_windows, unsigned seed) {
  // Growth is measured in the orbit norm: the Euclidean norm swings with each oscillating mode's
  // phase, which made a window's growth wrong by up to ±0.004 per period (a configuration whose
  // windows all grow in the orbit norm had one that decayed, and the reverse; docs/regions.md).
  // Where that energy is indefinite — a region past its own step limit, which production
  // substeps (0.95 of each region's own limit) are chosen to avoid — the Euclidean norm is the
  // one left, and the estimate says so (orbit_norm).
  HAPTICSIM_THROW_UNLESS(
      window_periods >= 1 && burn_in_periods >= window_periods && max_windows >= 1,
      "the stability estimate needs window_periods ≥ 1, burn_in_periods ≥ "
      "window_periods and max_windows ≥ 1");
  std::optional<CoupledStability> estimate =
      PowerIterate(burn_in_periods, window_periods, max_windows, true, seed);
  if (!estimate) estimate = PowerIterate(burn_in_periods, window_periods, max_windows, false, seed);
  return *estimate;
}

std::optional<CoupledStability> AsyncRegions::PowerIterate(int burn_in_periods, int window_periods,
                                                           int max_windows, bool orbit_norm,
                                                           unsigned seed) {
  auto norm = [&] { return orbit_norm ? OrbitNorm() : StateNorm(); };
  CoupledStability out;
  out.common_period_s = static_cast<double>(common_period_ticks_) / ticks_per_second_;
  out.orbit_norm = orbit_norm;
  SetRandomState(seed);
  const double start = norm();
  if (!(start > 0)) {
    Reset();
    return std::nullopt;
  }
  ScaleAll(1.0 / start);
  // Mean log growth per period over the last window_periods periods; after the burn-in, one value
  // per window. The burn-in's last window is the first comparison.
  double window_growth = 0, previous_growth = -INFINITY, worst_growth = -INFINITY;
  int windows = 0;
  const int window_begin = std::max(0, burn_in_periods - window_periods);
  for (int period = 1;; ++period) {
    AdvancePrimaryTo(period * common_period_ticks_);
    const double size = norm();
    out.periods = period;
    if (!std::isfinite(size) || size > 1e100) {
      out.spectral_radius = INFINITY;
      out.stable = false;
      Reset();
      return out;
    }
    if (!(size > 0)) {  // an indefinite orbit energy
      Reset();
      return std::nullopt;
    }
    if (period > window_begin) window_growth += std::log(size);
    ScaleAll(1.0 / size);
    if (period <= window_begin || (period - window_begin) % window_periods != 0) continue;
    const double growth = window_growth / window_periods;
    window_growth = 0;
    if (period <= burn_in_periods) {  // the burn-in's last window
      previous_growth = growth;
      continue;
    }
    ++windows;
    worst_growth = std::max(worst_growth, growth);
    // Done when a window already says unstable, or the growth has stopped rising: a mode that
    // grows (or decays slowest) but started small takes over gradually, and while it does each
    // window grows faster than the one before. A near-neutral configuration can rise for
    // seconds (docs/regions.md, "Coupled stability"); it gets up to max_windows windows.
    const bool unstable = growth >= std::log(CoupledStability::kStableBelow);
    const bool rising = growth - previous_growth > kStillRising * std::abs(growth);
    if (unstable || !rising || windows >= max_windows) break;
    previous_growth = growth;
  }
  out.spectral_radius = std::exp(worst_growth);
  out.stable = out.spectral_radius < CoupledStability::kStableBelow;
  Reset();
  return out;
}

std::vector<double> AsyncRegions::FreeDecayEnergies(int periods_per_checkpoint, int checkpoints,
                                                    unsigned seed) {
  SetRandomState(seed);
  std::vector<double> energies{Energy()};
  for (int c = 1; c <= checkpoints; ++c) {
    AdvancePrimaryTo(static_cast<std::int64_t>(c) * periods_per_checkpoint * common_period_ticks_);
    energies.push_back(Energy());
  }
  Reset();
  return energies;
}

}  // namespace hapticsim
