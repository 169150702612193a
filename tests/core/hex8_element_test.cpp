#include "core/fem/hex8_element.hpp"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

namespace hapticsim {
namespace {

Hex8Element::Matrix24 Ke() {
  Material material;  // E 10 kPa, ν 0.45
  return Hex8Element::Stiffness(0.02, material);
}

// The six rigid-body motions of the element: three translations, three small rotations.
Eigen::Matrix<double, 24, 6> RigidModes(double h) {
  Eigen::Matrix<double, 24, 6> modes = Eigen::Matrix<double, 24, 6>::Zero();
  for (int local = 0; local < 8; ++local) {
    const Eigen::Vector3d x(h * (local & 1), h * ((local >> 1) & 1), h * ((local >> 2) & 1));
    for (int c = 0; c < 3; ++c) modes(3 * local + c, c) = 1.0;
    for (int axis = 0; axis < 3; ++axis) {
      const Eigen::Vector3d w = Eigen::Vector3d::Unit(axis);
      modes.block<3, 1>(3 * local, 3 + axis) = w.cross(x);
    }
  }
  return modes;
}

TEST(Hex8Element, StiffnessIsSymmetric) {
  const auto k = Ke();
  EXPECT_EQ((k - k.transpose()).cwiseAbs().maxCoeff(), 0.0);
}

TEST(Hex8Element, HasExactlySixZeroEigenvaluesAndIsOtherwisePositive) {
  const auto k = Ke();
  Eigen::SelfAdjointEigenSolver<Hex8Element::Matrix24> solver(k);
  const auto& ev = solver.eigenvalues();  // ascending
  const double largest = ev.maxCoeff();
  for (int i = 0; i < 6; ++i) EXPECT_LT(std::abs(ev[i]), 1e-12 * largest) << "eigenvalue " << i;
  // Full integration: no hourglass modes, so the 7th eigenvalue is clearly positive.
  EXPECT_GT(ev[6], 1e-3 * largest);
}

TEST(Hex8Element, RigidBodyMotionsProduceNoForce) {
  const double h = 0.02;
  const auto k = Hex8Element::Stiffness(h, Material{});
  // Evaluated into a matrix: an Eigen product expression would refer to a destroyed temporary.
  const Eigen::Matrix<double, 24, 6> forces = k * RigidModes(h);
  EXPECT_LT(forces.cwiseAbs().maxCoeff(), 1e-12 * k.cwiseAbs().maxCoeff());
}

TEST(Hex8Element, StiffnessScalesLinearlyWithEdgeLength) {
  // Ke = h·(λA + μB): doubling h doubles every entry.
  const Material material;
  const auto k1 = Hex8Element::Stiffness(0.01, material);
  const auto k2 = Hex8Element::Stiffness(0.02, material);
  EXPECT_LT((k2 - 2.0 * k1).cwiseAbs().maxCoeff(), 1e-13 * k2.cwiseAbs().maxCoeff());
}

TEST(Hex8Element, UniformStrainEnergyMatchesContinuum) {
  // Under the uniform strain ε_xx = e (u_x = e·x) a cube of volume h³ stores
  // ½·(λ + 2μ)·e²·h³, which full integration reproduces exactly.
  const double h = 0.03, e = 1e-3;
  const Material material;
  const auto k = Hex8Element::Stiffness(h, material);
  Eigen::Matrix<double, 24, 1> u = Eigen::Matrix<double, 24, 1>::Zero();
  for (int local = 0; local < 8; ++local) u[3 * local] = e * h * (local & 1);
  const double energy = 0.5 * u.dot(k * u);
  const double expected =
      0.5 * (material.lame_lambda() + 2 * material.lame_mu()) * e * e * h * h * h;
  EXPECT_NEAR(energy, expected, 1e-12 * expected);
}

}  // namespace
}  // namespace hapticsim
