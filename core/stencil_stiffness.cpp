#include "core/stencil_stiffness.hpp"

#include <cassert>
#include <cmath>
#include <cstring>

#include "core/hex8_element.hpp"

namespace hapticsim {
namespace {

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

namespace {

// Four doubles in one SIMD register (GCC/Clang vector extension: AVX with -march=native, two
// SSE2 halves otherwise). Loads go through memcpy because neighbour rows are not aligned.
using Vec4 = double __attribute__((vector_size(32)));

inline Vec4 Load4(const double* p) {
  Vec4 v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

// ku_a[i … i+W) for one output component over all its couplings. W/4 vectors, each summed in
// two interleaved partial accumulators (even and odd terms): an FMA takes several cycles, so
// one dependency chain per vector would leave the FMA units idle.
template <int W>
inline void AccumulateChunk(const std::vector<StencilTerm>& terms, const double* u, double* out) {
  constexpr int kVectors = W / 4;
  Vec4 even[kVectors] = {}, odd[kVectors] = {};
  const size_t count = terms.size();
  size_t t = 0;
  for (; t + 1 < count; t += 2) {
    const double* src_even = u + terms[t].offset;
    const double* src_odd = u + terms[t + 1].offset;
    const double c_even = terms[t].coefficient, c_odd = terms[t + 1].coefficient;
    for (int v = 0; v < kVectors; ++v) {
      even[v] += c_even * Load4(src_even + 4 * v);
      odd[v] += c_odd * Load4(src_odd + 4 * v);
    }
  }
  if (t < count) {
    const double* src = u + terms[t].offset;
    for (int v = 0; v < kVectors; ++v) even[v] += terms[t].coefficient * Load4(src + 4 * v);
  }
  for (int v = 0; v < kVectors; ++v) {
    const Vec4 sum = even[v] + odd[v];
    std::memcpy(out + 4 * v, &sum, sizeof sum);
  }
}

}  // namespace

void StencilStiffness::ApplyRow(const double* u, double* ku, int iy, int iz) const {
  const int nx = grid_.nx();
  const std::ptrdiff_t n = grid_.num_nodes();
  const int row_class = 3 * AxisClass(iy, grid_.ny()) + 9 * AxisClass(iz, grid_.nz());
  const std::ptrdiff_t row = static_cast<std::ptrdiff_t>(grid_.Node(0, iy, iz));

  // One node with the stencil of its class (the two x faces, and the last few of a row).
  // Four partial sums, for the same reason as in AccumulateChunk.
  auto single = [&](int ix, const ClassStencil& stencil) {
    const std::ptrdiff_t i = row + ix;
    for (int a = 0; a < 3; ++a) {
      const auto& terms = stencil[a];
      double acc[4] = {};
      size_t t = 0;
      for (; t + 3 < terms.size(); t += 4) {
        for (int k = 0; k < 4; ++k) acc[k] += terms[t + k].coefficient * u[i + terms[t + k].offset];
      }
      for (; t < terms.size(); ++t) acc[0] += terms[t].coefficient * u[i + terms[t].offset];
      ku[a * n + i] = (acc[0] + acc[1]) + (acc[2] + acc[3]);
    }
  };
  // W consecutive interior nodes starting at ix.
  auto chunk = [&]<int W>(int ix) {
    const std::ptrdiff_t i = row + ix;
    const ClassStencil& inner = stencils_[row_class + 1];
    for (int a = 0; a < 3; ++a) AccumulateChunk<W>(inner[a], u + i, ku + a * n + i);
  };

  single(0, stencils_[row_class + 0]);
  int ix = 1;
  for (; ix + 16 <= nx - 1; ix += 16) chunk.template operator()<16>(ix);
  if (ix + 8 <= nx - 1) {
    chunk.template operator()<8>(ix);
    ix += 8;
  }
  if (ix + 4 <= nx - 1) {
    chunk.template operator()<4>(ix);
    ix += 4;
  }
  if (ix < nx - 1 && nx - 1 >= 5) {
    // Fewer than 4 interior nodes left: recompute the last 4 as one chunk. The overlap writes
    // the same values again, which is cheaper than scalar nodes.
    chunk.template operator()<4>(nx - 5);
    ix = nx - 1;
  }
  for (; ix < nx - 1; ++ix) single(ix, stencils_[row_class + 1]);
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
