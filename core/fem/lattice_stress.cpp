#include "core/fem/lattice_stress.hpp"

#include <cmath>

#include "core/error.hpp"

namespace hapticsim {
namespace {

// The von Mises stress at the centre of the lattice cell with lowest corner (ix, iy, iz).
double VonMisesAt(const ObjectState& state, double spacing_m, const Material& material, int ix,
                  int iy, int iz) {
  const double lambda = material.lame_lambda(), mu = material.lame_mu();
  // ∂u_c/∂x_d at the centre: the mean over the cell's 4 edges along d of their difference.
  double grad[3][3] = {};
  for (int corner = 0; corner < 8; ++corner) {
    const int b[3] = {corner & 1, (corner >> 1) & 1, (corner >> 2) & 1};
    const size_t i = state.Index(ix + b[0], iy + b[1], iz + b[2]);
    for (int d = 0; d < 3; ++d) {
      const double sign = b[d] ? 1.0 : -1.0;
      for (int c = 0; c < 3; ++c) grad[c][d] += sign * state.displacement_m[i + c];
    }
  }
  double strain[3][3];
  for (int c = 0; c < 3; ++c) {
    for (int d = 0; d < 3; ++d) strain[c][d] = (grad[c][d] + grad[d][c]) / (2.0 * 4.0 * spacing_m);
  }
  const double trace = strain[0][0] + strain[1][1] + strain[2][2];
  double s[3][3];
  for (int c = 0; c < 3; ++c) {
    for (int d = 0; d < 3; ++d) s[c][d] = 2 * mu * strain[c][d] + (c == d ? lambda * trace : 0);
  }
  const double normal = (s[0][0] - s[1][1]) * (s[0][0] - s[1][1]) +
                        (s[1][1] - s[2][2]) * (s[1][1] - s[2][2]) +
                        (s[2][2] - s[0][0]) * (s[2][2] - s[0][0]);
  const double shear = s[0][1] * s[0][1] + s[1][2] * s[1][2] + s[2][0] * s[2][0];
  return std::sqrt(0.5 * normal + 3.0 * shear);
}

}  // namespace

std::vector<double> VonMisesPerCell(const ObjectState& state, double spacing_m,
                                    const Material& material) {
  const auto [nx, ny, nz] = state.lattice_nodes;
  return VonMisesPerCell(state, spacing_m, {material},
                         std::vector<std::int16_t>(static_cast<size_t>(nx - 1) * (ny - 1) * (nz - 1), 0));
}

std::vector<double> VonMisesPerCell(const ObjectState& state, double spacing_m,
                                    const std::vector<Material>& materials,
                                    const std::vector<std::int16_t>& cell_material) {
  const auto [nx, ny, nz] = state.lattice_nodes;
  HAPTICSIM_THROW_UNLESS(cell_material.size() == static_cast<size_t>(nx - 1) * (ny - 1) * (nz - 1),
                         "internal: the cell materials are not the lattice's cells");
  std::vector<double> out;
  out.reserve(cell_material.size());
  size_t cell = 0;
  for (int ix = 0; ix + 1 < nx; ++ix) {
    for (int iy = 0; iy + 1 < ny; ++iy) {
      for (int iz = 0; iz + 1 < nz; ++iz, ++cell) {
        const std::int16_t m = cell_material[cell];
        out.push_back(m < 0 ? 0.0 : VonMisesAt(state, spacing_m, materials.at(m), ix, iy, iz));
      }
    }
  }
  return out;
}

}  // namespace hapticsim
