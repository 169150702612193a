// The von Mises stress `hapticsim simulate --vtk` writes per cell (VonMisesPerCell), against
// closed forms of linear elasticity: uniaxial strain, simple shear and a rigid rotation.
#include "core/fem/lattice_stress.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>

namespace hapticsim {
namespace {

constexpr int kN = 5;
constexpr double kH = 0.01;

ObjectState Field(const std::function<std::array<double, 3>(double, double, double)>& u) {
  ObjectState state;
  state.lattice_nodes = {kN, kN, kN};
  state.displacement_m.resize(3 * kN * kN * kN);
  for (int ix = 0; ix < kN; ++ix) {
    for (int iy = 0; iy < kN; ++iy) {
      for (int iz = 0; iz < kN; ++iz) {
        const auto v = u(ix * kH, iy * kH, iz * kH);
        for (int c = 0; c < 3; ++c) state.displacement_m[state.Index(ix, iy, iz) + c] = v[c];
      }
    }
  }
  return state;
}

TEST(VonMisesPerCell, UniaxialStrainIsTwiceMuTimesTheStrain) {
  const Material material;  // E 10 kPa, ν 0.45
  const double strain = 1e-3;
  const auto stress = VonMisesPerCell(Field([&](double x, double, double) {
                                        return std::array<double, 3>{strain * x, 0, 0};
                                      }),
                                      kH, material);
  ASSERT_EQ(stress.size(), static_cast<size_t>((kN - 1) * (kN - 1) * (kN - 1)));
  for (double s : stress) EXPECT_NEAR(s, 2 * material.lame_mu() * strain, 1e-12);
}

TEST(VonMisesPerCell, SimpleShearIsRootThreeTimesTheShearStress) {
  const Material material;
  const double gamma = 2e-3;
  for (double s : VonMisesPerCell(Field([&](double, double y, double) {
                                    return std::array<double, 3>{gamma * y, 0, 0};
                                  }),
                                  kH, material)) {
    EXPECT_NEAR(s, std::sqrt(3.0) * material.lame_mu() * gamma, 1e-12);
  }
}

TEST(VonMisesPerCell, ARigidRotationAndTranslationCarryNoStress) {
  const std::array<double, 3> w{1e-3, -2e-3, 3e-3}, t{1e-2, 2e-2, -3e-2};
  for (double s : VonMisesPerCell(Field([&](double x, double y, double z) {
                                    // u = t + ω × x, infinitesimal: its symmetric gradient is 0.
                                    return std::array<double, 3>{t[0] + w[1] * z - w[2] * y,
                                                                 t[1] + w[2] * x - w[0] * z,
                                                                 t[2] + w[0] * y - w[1] * x};
                                  }),
                                  kH, Material{})) {
    // Round-off only: the uniaxial case's stress at this size of strain is 3.4 Pa.
    EXPECT_NEAR(s, 0.0, 1e-9);
  }
}

}  // namespace
}  // namespace hapticsim
