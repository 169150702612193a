#include "core/fem/stencil_stiffness.hpp"

#include <cassert>

#include "core/fem/cpu_dispatch.hpp"
#include "core/fem/hex8_element.hpp"

namespace hapticsim {
namespace {

// Whether the cell on a node's low (−1) or high (0) side along one axis exists, for a node of
// axis class c (0 = low face, 1 = inside, 2 = high face).
bool CellExists(int side, int axis_class) { return side == -1 ? axis_class != 0 : axis_class != 2; }

}  // namespace

StencilStiffness::StencilStiffness(const HexGrid& grid, const Material& material)
    : StiffnessOperator(grid.num_dofs()), grid_(grid) {
  const Hex8Element::Matrix24 ke = Hex8Element::Stiffness(grid.spacing(), material);
  const std::ptrdiff_t sy = grid.nx();
  const std::ptrdiff_t sz = static_cast<std::ptrdiff_t>(grid.nx()) * grid.ny();
  for (int cls = 0; cls < 27; ++cls) {
    const std::array<int, 3> axis_class{cls % 3, (cls / 3) % 3, cls / 9};
    unsigned cells = 0;
    for (unsigned cell = 0; cell < 8; ++cell) {
      bool exists = true;
      for (int axis = 0; axis < 3; ++axis) {
        exists = exists && CellExists(-static_cast<int>((cell >> axis) & 1), axis_class[axis]);
      }
      if (exists) cells |= 1u << cell;
    }
    stencils_[cls] = MakeNodeStencil(ke, cells, grid.num_nodes(), sy, sz);
  }
}

HAPTICSIM_KERNEL_CLONES
void StencilStiffness::ApplyRows(const double* u, double* ku) const {
  const int nx = grid_.nx();
  const std::ptrdiff_t n = grid_.num_nodes();
  for (int iz = 0; iz < grid_.nz(); ++iz) {
    for (int iy = 0; iy < grid_.ny(); ++iy) {
      const int row_class = 3 * AxisClass(iy, grid_.ny()) + 9 * AxisClass(iz, grid_.nz());
      const std::ptrdiff_t row = static_cast<std::ptrdiff_t>(grid_.Node(0, iy, iz));
      // The two x faces one node each, the interior between them as one run.
      ApplyStencilAt(stencils_[row_class + 0], u, ku, row, n);
      ApplyStencilRun(stencils_[row_class + 1], u, ku, row + 1, nx - 2, n);
      ApplyStencilAt(stencils_[row_class + 2], u, ku, row + nx - 1, n);
    }
  }
}

void StencilStiffness::Apply(const Eigen::Ref<const Eigen::VectorXd>& u,
                             Eigen::Ref<Eigen::VectorXd> ku) const {
  assert(u.size() == num_dofs() && ku.size() == num_dofs());
  ApplyRows(u.data(), ku.data());
}

Eigen::VectorXd StencilStiffness::Diagonal() const {
  Eigen::VectorXd diagonal(num_dofs());
  const std::ptrdiff_t n = grid_.num_nodes();
  for (int node = 0; node < grid_.num_nodes(); ++node) {
    const auto [ix, iy, iz] = grid_.NodeIndices(node);
    const int cls =
        AxisClass(ix, grid_.nx()) + 3 * AxisClass(iy, grid_.ny()) + 9 * AxisClass(iz, grid_.nz());
    for (int a = 0; a < 3; ++a) {
      diagonal[a * n + node] = 0.0;
      for (const StencilTerm& t : stencils_[cls][a]) {
        if (t.offset == a * n) diagonal[a * n + node] = t.coefficient;
      }
    }
  }
  return diagonal;
}

double StencilStiffness::FlopsPerApply() const {
  double flops = 0.0;
  for (int node = 0; node < grid_.num_nodes(); ++node) {
    const auto [ix, iy, iz] = grid_.NodeIndices(node);
    const int cls =
        AxisClass(ix, grid_.nx()) + 3 * AxisClass(iy, grid_.ny()) + 9 * AxisClass(iz, grid_.nz());
    for (int a = 0; a < 3; ++a) flops += 2.0 * static_cast<double>(stencils_[cls][a].size());
  }
  return flops;
}

}  // namespace hapticsim
