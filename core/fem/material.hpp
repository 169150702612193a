#pragma once

namespace hapticsim {

/** Isotropic linear-elastic material with mass-proportional damping (SI units). */
struct Material {
  double youngs_modulus_pa = 10e3;  ///< E, Pa
  double poisson_ratio = 0.45;      ///< ν, dimensionless, in (−1, 0.5)
  double density_kg_m3 = 1000.0;    ///< ρ, kg/m³
  double damping_per_s = 10.0;      ///< d in C = d·M, 1/s

  /** First Lamé parameter λ = Eν / ((1 + ν)(1 − 2ν)), Pa. */
  double lame_lambda() const {
    const double nu = poisson_ratio;
    return youngs_modulus_pa * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
  }
  /** Shear modulus μ = E / (2(1 + ν)), Pa. */
  double lame_mu() const { return youngs_modulus_pa / (2.0 * (1.0 + poisson_ratio)); }
};

}  // namespace hapticsim
