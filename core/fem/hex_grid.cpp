#include "core/fem/hex_grid.hpp"

#include <cmath>
#include <string>

#include "core/error.hpp"

namespace hapticsim {

HexGrid::HexGrid(int nx, int ny, int nz, double spacing_m)
    : nx_(nx), ny_(ny), nz_(nz), spacing_(spacing_m) {
  HAPTICSIM_THROW_UNLESS(nx >= 2 && ny >= 2 && nz >= 2,
                         "a hexahedral grid needs at least 2 nodes per axis, got " +
                             std::to_string(nx) + "×" + std::to_string(ny) + "×" +
                             std::to_string(nz));
  HAPTICSIM_THROW_UNLESS(std::isfinite(spacing_m) && spacing_m > 0,
                         "node spacing must be a finite positive length in metres");
}

std::array<int, 3> HexGrid::NodeIndices(int node) const {
  const int ix = node % nx_;
  const int iy = (node / nx_) % ny_;
  const int iz = node / (nx_ * ny_);
  return {ix, iy, iz};
}

std::array<double, 3> HexGrid::NodePosition(int node) const {
  const auto [ix, iy, iz] = NodeIndices(node);
  return {ix * spacing_, iy * spacing_, iz * spacing_};
}

std::array<int, 8> HexGrid::ElementNodes(int ex, int ey, int ez) const {
  std::array<int, 8> nodes{};
  for (int local = 0; local < 8; ++local) {
    nodes[local] = Node(ex + (local & 1), ey + ((local >> 1) & 1), ez + ((local >> 2) & 1));
  }
  return nodes;
}

}  // namespace hapticsim
