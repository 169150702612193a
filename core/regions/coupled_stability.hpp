#pragma once

namespace hapticsim {

/** The spectral radius of the map that advances the coupled state by one common period
 *  (AsyncRegions::EstimateCoupledStability). */
struct CoupledStability {
  double spectral_radius = 0;  ///< per common period; < 1 decays, > 1 grows
  double common_period_s = 0;  ///< the shortest time after which every region's schedule repeats
  int periods = 0;             ///< periods of power iteration used
  bool orbit_norm = true;      ///< false: the orbit energy was indefinite, the Euclidean norm used
  bool stable = false;         ///< spectral_radius < kStableBelow
  /** Margin below 1 that counts as stable: a mode decaying slower than this is refused. */
  static constexpr double kStableBelow = 1.0 - 1e-6;
};

}  // namespace hapticsim
