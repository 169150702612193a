#include "core/fem/hex8_element.hpp"

#include <array>
#include <cmath>

namespace hapticsim {
namespace {

using Matrix6x24 = Eigen::Matrix<double, 6, 24>;

// Strain-displacement matrix of the unit cube at natural coordinates (xi, eta, zeta) ∈ [−1,1]³.
// x = (ξ + 1)/2 on the unit cube, so ∂N/∂x = 2·∂N/∂ξ.
Matrix6x24 UnitStrainDisplacement(double xi, double eta, double zeta) {
  Matrix6x24 b = Matrix6x24::Zero();
  for (int local = 0; local < 8; ++local) {
    const double sx = (local & 1) ? 1.0 : -1.0;
    const double sy = ((local >> 1) & 1) ? 1.0 : -1.0;
    const double sz = ((local >> 2) & 1) ? 1.0 : -1.0;
    // N = (1 + sx ξ)(1 + sy η)(1 + sz ζ)/8
    const double dx = 2.0 * sx * (1 + sy * eta) * (1 + sz * zeta) / 8.0;
    const double dy = 2.0 * sy * (1 + sx * xi) * (1 + sz * zeta) / 8.0;
    const double dz = 2.0 * sz * (1 + sx * xi) * (1 + sy * eta) / 8.0;
    const int c = 3 * local;
    b(0, c + 0) = dx;  // ε_xx
    b(1, c + 1) = dy;  // ε_yy
    b(2, c + 2) = dz;  // ε_zz
    b(3, c + 0) = dy;  // γ_xy
    b(3, c + 1) = dx;
    b(4, c + 1) = dz;  // γ_yz
    b(4, c + 2) = dy;
    b(5, c + 0) = dz;  // γ_xz
    b(5, c + 2) = dx;
  }
  return b;
}

// ∫ Bᵀ D B over the unit cube with 2×2×2 Gauss points (weights 1, det J = 1/8).
Hex8Element::Matrix24 IntegrateUnitCube(const Eigen::Matrix<double, 6, 6>& d) {
  const double g = 1.0 / std::sqrt(3.0);
  const std::array<double, 2> points{-g, g};
  Hex8Element::Matrix24 k = Hex8Element::Matrix24::Zero();
  for (double xi : points) {
    for (double eta : points) {
      for (double zeta : points) {
        const Matrix6x24 b = UnitStrainDisplacement(xi, eta, zeta);
        k.noalias() += b.transpose() * d * b * (1.0 / 8.0);
      }
    }
  }
  // Symmetrise exactly: quadrature round-off must not leave a one-ulp asymmetry.
  return 0.5 * (k + k.transpose());
}

}  // namespace

const Hex8Element::Matrix24& Hex8Element::UnitLambdaPart() {
  static const Matrix24 a = [] {
    Eigen::Matrix<double, 6, 6> d = Eigen::Matrix<double, 6, 6>::Zero();
    d.topLeftCorner<3, 3>().setOnes();
    return IntegrateUnitCube(d);
  }();
  return a;
}

const Hex8Element::Matrix24& Hex8Element::UnitMuPart() {
  static const Matrix24 b = [] {
    Eigen::Matrix<double, 6, 1> diag;
    diag << 2, 2, 2, 1, 1, 1;
    return IntegrateUnitCube(diag.asDiagonal().toDenseMatrix());
  }();
  return b;
}

Hex8Element::Matrix24 Hex8Element::Stiffness(double edge_m, const Material& material) {
  return edge_m * (material.lame_lambda() * UnitLambdaPart() + material.lame_mu() * UnitMuPart());
}

}  // namespace hapticsim
