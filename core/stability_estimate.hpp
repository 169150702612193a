#pragma once

#include "core/elastic_model.hpp"

namespace hapticsim {

/**
 * The critical time step of central difference for a model, dt_crit = 2/ω_max with
 * ω_max² = λ_max(M⁻¹K) on the free DOFs (fixed and driven DOFs removed).
 *
 * With C = d·M and centred velocities, damping does not lower this limit (a damped mode obeys
 * (1 + d·dt/2)λ² − (2 − ω²dt²)λ + (1 − d·dt/2) = 0, whose roots leave the unit circle exactly
 * when ω·dt > 2), so 2/ω_max is the limit for every d ≥ 0.
 */
struct StabilityEstimate {
  double omega_max_rad_s = 0;    ///< ω_max from power iteration, rad/s
  double critical_dt_s = 0;      ///< 2/ω_max, s
  double element_bound_dt_s = 0; ///< 2/ω_e from the element-level bound ω_max ≤ ω_e, s (≤ critical)
  int iterations = 0;            ///< power iterations used
  bool converged = false;        ///< the Rayleigh quotient settled to the requested tolerance

  /** True when dt is below the critical step (the run is predicted stable). */
  bool IsStable(double dt_s) const { return dt_s < critical_dt_s; }
};

struct PowerIterationOptions {
  /** Stop when the Rayleigh quotient grew by less than this (relative) over `window` steps. */
  double relative_tolerance = 1e-9;
  int window = 20;
  int max_iterations = 20000;
};

/**
 * Power iteration on the symmetric form M^(-1/2) K M^(-1/2) restricted to the free DOFs, from a
 * fixed pseudo-random start (deterministic). The Rayleigh quotient rises monotonically towards
 * λ_max, so an unconverged estimate errs towards a larger dt; the element bound is the safe side.
 */
StabilityEstimate EstimateStability(const ElasticModel& model,
                                    const PowerIterationOptions& options = {});

/**
 * Element-level bound: ω_max² ≤ max over elements of λ_max(M_e⁻¹ K_e), with M_e the element's
 * share ρh³/8 of each node's lumped mass. Returns 2/√bound, s — never above the true limit.
 */
double ElementBoundCriticalDt(const ElasticModel& model);

}  // namespace hapticsim
