#pragma once

#include <Eigen/Core>

#include "core/fem/material.hpp"

namespace hapticsim {

/**
 * The trilinear 8-node hexahedron (C3D8) on a cube of edge h, fully integrated with 2×2×2 Gauss
 * points, for isotropic linear elasticity.
 *
 * Local nodes are numbered bx + 2·by + 4·bz for corner offsets (bx, by, bz) ∈ {0,1}³; local
 * degrees of freedom are node-major: 3·local_node + component.
 *
 * For a cube the stiffness separates into two fixed matrices:
 *   Ke = h · (λ·A + μ·B),
 * where A = ∫ Bᵀ m mᵀ B and B = ∫ Bᵀ diag(2,2,2,1,1,1) B over the unit cube (B the
 * strain-displacement matrix with engineering shear strains, m = [1 1 1 0 0 0]ᵀ). They are
 * computed once.
 */
class Hex8Element {
 public:
  using Matrix24 = Eigen::Matrix<double, 24, 24>;

  /** λ-part A of the unit-cube stiffness (see class comment). */
  static const Matrix24& UnitLambdaPart();
  /** μ-part B of the unit-cube stiffness (see class comment). */
  static const Matrix24& UnitMuPart();

  /** Element stiffness h·(λA + μB) in N/m for a cube of edge `edge_m`. */
  static Matrix24 Stiffness(double edge_m, const Material& material);
};

}  // namespace hapticsim
