#include "core/fem/stencil_kernels.hpp"

#include <algorithm>
#include <cmath>
#include <map>

namespace hapticsim {

NodeStencil MakeNodeStencil(const CellMatrices& cells, std::ptrdiff_t n, std::ptrdiff_t sy,
                            std::ptrdiff_t sz) {
  // One threshold for the whole node, from the stiffest cell: with one matrix everywhere it is
  // that matrix's, as it has always been (StencilStiffness stays bit-identical).
  double largest = 0.0;
  for (const Hex8Element::Matrix24* ke : cells) {
    if (ke != nullptr) largest = std::max(largest, ke->cwiseAbs().maxCoeff());
  }
  const double drop_below = 1e-13 * largest;
  NodeStencil stencil;
  for (int dz = -1; dz <= 1; ++dz) {
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        const std::array<int, 3> d{dx, dy, dz};
        Eigen::Matrix3d block = Eigen::Matrix3d::Zero();
        // Sum over the cells around the node that are present and also contain the neighbour.
        for (int cell = 0; cell < 8; ++cell) {
          if (cells[static_cast<size_t>(cell)] == nullptr) continue;
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
          if (contributes) {
            block += cells[static_cast<size_t>(cell)]->block<3, 3>(3 * local_i, 3 * local_j);
          }
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

NodeStencil MakeNodeStencil(const Hex8Element::Matrix24& ke, unsigned cell_mask, std::ptrdiff_t n,
                            std::ptrdiff_t sy, std::ptrdiff_t sz) {
  CellMatrices cells{};
  for (unsigned cell = 0; cell < 8; ++cell) {
    cells[cell] = (cell_mask & (1u << cell)) ? &ke : nullptr;
  }
  return MakeNodeStencil(cells, n, sy, sz);
}

LaneStencil MergeNodeStencils(const std::array<const NodeStencil*, 4>& nodes) {
  LaneStencil merged;
  for (size_t a = 0; a < 3; ++a) {
    // By offset, so the lanes' reads sweep u in one direction as a node stencil's do.
    std::map<std::ptrdiff_t, std::array<double, 4>> by_offset;
    for (size_t k = 0; k < 4; ++k) {
      for (const StencilTerm& term : (*nodes[k])[a]) {
        by_offset.try_emplace(term.offset, std::array<double, 4>{}).first->second[k] =
            term.coefficient;
      }
    }
    merged[a].reserve(by_offset.size());
    for (const auto& [offset, coefficient] : by_offset) merged[a].push_back({offset, coefficient});
  }
  return merged;
}

bool LaneReadsInside(const LaneStencil& stencil, std::ptrdiff_t first, std::ptrdiff_t n) {
  for (const auto& terms : stencil) {
    for (const LaneTerm& term : terms) {
      if (first + term.offset < 0 || first + 3 + term.offset >= 3 * n) return false;
    }
  }
  return true;
}

}  // namespace hapticsim
