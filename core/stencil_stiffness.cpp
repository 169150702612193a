#include "core/stencil_stiffness.hpp"

#include <cassert>
#include <cmath>

#include "core/hex8_element.hpp"

namespace hapticsim {
namespace {

// Nodes per vectorised chunk along x: 8 doubles per output component stay in registers while
// all couplings of the chunk are accumulated, and each output is written once.
constexpr int kChunk = 8;

// Exists-test for the element at per-axis offset e ∈ {−1, 0} from a node of axis class c
// (0 = low face, 1 = inside, 2 = high face).
bool ElementExists(int e, int axis_class) { return e == -1 ? axis_class != 0 : axis_class != 2; }

}  // namespace

StencilStiffness::StencilStiffness(const HexGrid& grid, const Material& material)
    : StiffnessOperator(grid.num_dofs()), grid_(grid) {
  const Hex8Element::Matrix24 ke = Hex8Element::Stiffness(grid.spacing(), material);
  const double drop_below = 1e-13 * ke.cwiseAbs().maxCoeff();
  const std::ptrdiff_t n = grid.num_nodes();
  const std::ptrdiff_t sy = grid.nx();
  const std::ptrdiff_t sz = static_cast<std::ptrdiff_t>(grid.nx()) * grid.ny();

  for (int cls = 0; cls < 27; ++cls) {
    const std::array<int, 3> axis_class{cls % 3, (cls / 3) % 3, cls / 9};
    for (int dz = -1; dz <= 1; ++dz) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const std::array<int, 3> d{dx, dy, dz};
          Eigen::Matrix3d block = Eigen::Matrix3d::Zero();
          // Sum over the up to 8 elements around the node that also contain the neighbour.
          for (int e_bits = 0; e_bits < 8; ++e_bits) {
            const std::array<int, 3> e{-(e_bits & 1), -((e_bits >> 1) & 1), -((e_bits >> 2) & 1)};
            bool contributes = true;
            int local_i = 0, local_j = 0;
            for (int axis = 0; axis < 3; ++axis) {
              const int li = -e[axis];
              const int lj = d[axis] - e[axis];
              if (!ElementExists(e[axis], axis_class[axis]) || lj < 0 || lj > 1) {
                contributes = false;
                break;
              }
              local_i |= li << axis;
              local_j |= lj << axis;
            }
            if (!contributes) continue;
            block += ke.block<3, 3>(3 * local_i, 3 * local_j);
          }
          const std::ptrdiff_t stride = dx + dy * sy + dz * sz;
          for (int a = 0; a < 3; ++a) {
            for (int b = 0; b < 3; ++b) {
              if (std::abs(block(a, b)) > drop_below) {
                stencils_[cls][a].push_back({b * n + stride, block(a, b)});
              }
            }
          }
        }
      }
    }
  }
}

void StencilStiffness::ApplyRow(const double* u, double* ku, int iy, int iz) const {
  const int nx = grid_.nx();
  const std::ptrdiff_t n = grid_.num_nodes();
  const int row_class = 3 * AxisClass(iy, grid_.ny()) + 9 * AxisClass(iz, grid_.nz());
  const std::ptrdiff_t row = static_cast<std::ptrdiff_t>(grid_.Node(0, iy, iz));

  // One node with the stencil of its class (the two x faces, and the tail of the row).
  auto single = [&](int ix, const ClassStencil& stencil) {
    const std::ptrdiff_t i = row + ix;
    for (int a = 0; a < 3; ++a) {
      double acc = 0.0;
      for (const Term& t : stencil[a]) acc += t.coefficient * u[i + t.offset];
      ku[a * n + i] = acc;
    }
  };

  single(0, stencils_[row_class + 0]);
  const ClassStencil& inner = stencils_[row_class + 1];
  int ix = 1;
  for (; ix + kChunk <= nx - 1; ix += kChunk) {
    const std::ptrdiff_t i = row + ix;
    for (int a = 0; a < 3; ++a) {
      double acc[kChunk] = {};
      for (const Term& t : inner[a]) {
        const double* src = u + i + t.offset;
        for (int w = 0; w < kChunk; ++w) acc[w] += t.coefficient * src[w];
      }
      for (int w = 0; w < kChunk; ++w) ku[a * n + i + w] = acc[w];
    }
  }
  for (; ix < nx - 1; ++ix) single(ix, inner);
  single(nx - 1, stencils_[row_class + 2]);
}

void StencilStiffness::Apply(const Eigen::Ref<const Eigen::VectorXd>& u,
                             Eigen::Ref<Eigen::VectorXd> ku) const {
  assert(u.size() == num_dofs() && ku.size() == num_dofs());
  for (int iz = 0; iz < grid_.nz(); ++iz) {
    for (int iy = 0; iy < grid_.ny(); ++iy) ApplyRow(u.data(), ku.data(), iy, iz);
  }
}

Eigen::VectorXd StencilStiffness::Diagonal() const {
  Eigen::VectorXd diagonal(num_dofs());
  const std::ptrdiff_t n = grid_.num_nodes();
  for (int node = 0; node < grid_.num_nodes(); ++node) {
    const auto [ix, iy, iz] = grid_.NodeIndices(node);
    const int cls = AxisClass(ix, grid_.nx()) + 3 * AxisClass(iy, grid_.ny()) +
                    9 * AxisClass(iz, grid_.nz());
    for (int a = 0; a < 3; ++a) {
      diagonal[a * n + node] = 0.0;
      for (const Term& t : stencils_[cls][a]) {
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
    const int cls = AxisClass(ix, grid_.nx()) + 3 * AxisClass(iy, grid_.ny()) +
                    9 * AxisClass(iz, grid_.nz());
    for (int a = 0; a < 3; ++a) flops += 2.0 * static_cast<double>(stencils_[cls][a].size());
  }
  return flops;
}

}  // namespace hapticsim
