#include "core/fem/stencil_kernels.hpp"

#include <cmath>

namespace hapticsim {

NodeStencil MakeNodeStencil(const Hex8Element::Matrix24& ke, unsigned cell_mask, std::ptrdiff_t n,
                            std::ptrdiff_t sy, std::ptrdiff_t sz) {
  const double drop_below = 1e-13 * ke.cwiseAbs().maxCoeff();
  NodeStencil stencil;
  for (int dz = -1; dz <= 1; ++dz) {
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        const std::array<int, 3> d{dx, dy, dz};
        Eigen::Matrix3d block = Eigen::Matrix3d::Zero();
        // Sum over the cells around the node that are present and also contain the neighbour.
        for (int cell = 0; cell < 8; ++cell) {
          if (!(cell_mask & (1u << cell))) continue;
          const std::array<int, 3> e{-(cell & 1), -((cell >> 1) & 1), -((cell >> 2) & 1)};
          bool contributes = true;
          int local_i = 0, local_j = 0;
          for (int axis = 0; axis < 3; ++axis) {
            const int li = -e[axis];
            const int lj = d[axis] - e[axis];
            if (lj < 0 || lj > 1) {
              contributes = false;
              break;
            }
            local_i |= li << axis;
            local_j |= lj << axis;
          }
          if (contributes) block += ke.block<3, 3>(3 * local_i, 3 * local_j);
        }
        const std::ptrdiff_t stride = dx + dy * sy + dz * sz;
        for (int a = 0; a < 3; ++a) {
          for (int b = 0; b < 3; ++b) {
            if (std::abs(block(a, b)) > drop_below) {
              stencil[a].push_back({b * n + stride, block(a, b)});
            }
          }
        }
      }
    }
  }
  return stencil;
}

}  // namespace hapticsim
