#pragma once

#include <array>
#include <cstddef>
#include <cstring>
#include <vector>

#include "core/fem/cpu_dispatch.hpp"
#include "core/fem/hex8_element.hpp"

namespace hapticsim {

/**
 * One coupling of a stencil: ku_a[i] += coefficient · u[i + offset], where offset already includes
 * the component block of the source (b·N) and the neighbour's node stride.
 */
struct StencilTerm {
  std::ptrdiff_t offset;
  double coefficient;
};

/** A node's stencil on a structured grid, split by output component a. */
using NodeStencil = std::array<std::vector<StencilTerm>, 3>;

/**
 * The element matrices of the 8 cells around a node: cell c lies on the node's low side along
 * every axis j whose bit j of c is set (high side where clear); null where no element is (an
 * empty cell, or one outside the grid).
 */
using CellMatrices = std::array<const Hex8Element::Matrix24*, 8>;

/**
 * The stencil of a node from the cells around it that are present: the sum of their
 * element-matrix blocks (in cell order), couplings below 10⁻¹³ of the largest entry of those
 * matrices dropped; on a grid of n nodes with node strides sy (y) and sz (z), component-blocked.
 * No cell present: an empty stencil (ApplyStencilAt/Run write ku = 0).
 */
NodeStencil MakeNodeStencil(const CellMatrices& cells, std::ptrdiff_t n, std::ptrdiff_t sy,
                            std::ptrdiff_t sz);

/**
 * The same with one element matrix `ke` in every cell present: bit c of `cell_mask` set for
 * cell c present.
 */
NodeStencil MakeNodeStencil(const Hex8Element::Matrix24& ke, unsigned cell_mask, std::ptrdiff_t n,
                            std::ptrdiff_t sy, std::ptrdiff_t sz);

namespace stencil_detail {

// Four doubles in one SIMD register (GCC/Clang vector extension: one AVX register in a kernel
// compiled for AVX2 or AVX-512, two SSE halves in the baseline's). Loads go through memcpy because
// neighbour rows are not aligned. A Vec4 is never passed or returned by value: without AVX that
// is an ABI change GCC warns of and clang refuses.
using Vec4 = double __attribute__((vector_size(32)));

// sum += c · p[0 … 4)
HAPTICSIM_KERNEL_INLINE void AddScaled4(Vec4& sum, double c, const double* p) {
  Vec4 v;
  std::memcpy(&v, p, sizeof v);
  sum += c * v;
}

// ku_a[i … i+W) for one output component over all its couplings. W/4 vectors, each summed in
// two interleaved partial accumulators (even and odd terms): an FMA takes several cycles, so
// one dependency chain per vector would leave the FMA units idle.
template <int W>
HAPTICSIM_KERNEL_INLINE void AccumulateChunk(const std::vector<StencilTerm>& terms, const double* u,
                                             double* out) {
  constexpr int kVectors = W / 4;
  Vec4 even[kVectors] = {}, odd[kVectors] = {};
  const size_t count = terms.size();
  size_t t = 0;
  for (; t + 1 < count; t += 2) {
    const double* src_even = u + terms[t].offset;
    const double* src_odd = u + terms[t + 1].offset;
    const double c_even = terms[t].coefficient, c_odd = terms[t + 1].coefficient;
    for (int v = 0; v < kVectors; ++v) {
      AddScaled4(even[v], c_even, src_even + 4 * v);
      AddScaled4(odd[v], c_odd, src_odd + 4 * v);
    }
  }
  if (t < count) {
    const double* src = u + terms[t].offset;
    for (int v = 0; v < kVectors; ++v) AddScaled4(even[v], terms[t].coefficient, src + 4 * v);
  }
  for (int v = 0; v < kVectors; ++v) {
    const Vec4 sum = even[v] + odd[v];
    std::memcpy(out + 4 * v, &sum, sizeof sum);
  }
}

// ku at W consecutive nodes from node i, all three components.
template <int W>
HAPTICSIM_KERNEL_INLINE void AccumulateNodes(const NodeStencil& stencil, const double* u,
                                             double* ku, std::ptrdiff_t i, std::ptrdiff_t n) {
  for (int a = 0; a < 3; ++a) AccumulateChunk<W>(stencil[a], u + i, ku + a * n + i);
}

}  // namespace stencil_detail

/**
 * ku at node i (all three components) by its stencil; n nodes per component block. Four partial
 * sums, for the same reason as in AccumulateChunk.
 */
HAPTICSIM_KERNEL_INLINE void ApplyStencilAt(const NodeStencil& stencil, const double* u, double* ku,
                                            std::ptrdiff_t i, std::ptrdiff_t n) {
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
}

/**
 * ku at the `length` consecutive nodes (along x) from node `first` that share one stencil: in
 * vectors of 16, 8 and 4 nodes, a tail of fewer than 4 as the run's last 4 again (the overlap
 * writes the same values, cheaper than scalar nodes), single nodes only in runs shorter than 4.
 */
HAPTICSIM_KERNEL_INLINE void ApplyStencilRun(const NodeStencil& stencil, const double* u,
                                             double* ku, std::ptrdiff_t first, int length,
                                             std::ptrdiff_t n) {
  using stencil_detail::AccumulateNodes;
  if (length < 4) {
    for (int k = 0; k < length; ++k) ApplyStencilAt(stencil, u, ku, first + k, n);
    return;
  }
  int k = 0;
  for (; k + 16 <= length; k += 16) AccumulateNodes<16>(stencil, u, ku, first + k, n);
  if (k + 8 <= length) {
    AccumulateNodes<8>(stencil, u, ku, first + k, n);
    k += 8;
  }
  if (k + 4 <= length) {
    AccumulateNodes<4>(stencil, u, ku, first + k, n);
    k += 4;
  }
  if (k < length) AccumulateNodes<4>(stencil, u, ku, first + length - 4, n);
}

/**
 * The stencils of 4 consecutive nodes along x that do not share one, merged lane by lane: lane k
 * is node k's stencil, ku_a[i+k] += coefficient[k] · u[i + k + offset], 0 where node k has no
 * such coupling. Where a node's stencil changes every node or two (materials changing along x,
 * the faces of an object), this keeps the vector kernel instead of the scalar one.
 */
struct LaneTerm {
  std::ptrdiff_t offset;
  std::array<double, 4> coefficient;
};
using LaneStencil = std::array<std::vector<LaneTerm>, 3>;

/** The lane stencil of the 4 nodes whose stencils are `nodes` (lane k: nodes[k]), by offset. */
LaneStencil MergeNodeStencils(const std::array<const NodeStencil*, 4>& nodes);

/**
 * Whether every lane's reads, u[first + k + offset] for all terms, fall inside u[0, 3n): a lane
 * also reads the neighbours of the other lanes' couplings (times 0), up to 3 nodes further.
 */
bool LaneReadsInside(const LaneStencil& stencil, std::ptrdiff_t first, std::ptrdiff_t n);

/**
 * ku at the 4 nodes from `first` by their merged stencil. A lane multiplies u where its node has
 * no coupling by 0, so u must be finite (an infinite u gives NaN in nodes it does not touch).
 */
HAPTICSIM_KERNEL_INLINE void ApplyLaneStencil(const LaneStencil& stencil, const double* u,
                                              double* ku, std::ptrdiff_t first, std::ptrdiff_t n) {
  using stencil_detail::Vec4;
  for (int a = 0; a < 3; ++a) {
    const auto& terms = stencil[a];
    Vec4 even = {}, odd = {};  // two dependency chains, as in AccumulateChunk
    Vec4 c, v;
    size_t t = 0;
    for (; t + 1 < terms.size(); t += 2) {
      std::memcpy(&c, terms[t].coefficient.data(), sizeof c);
      std::memcpy(&v, u + first + terms[t].offset, sizeof v);
      even += c * v;
      std::memcpy(&c, terms[t + 1].coefficient.data(), sizeof c);
      std::memcpy(&v, u + first + terms[t + 1].offset, sizeof v);
      odd += c * v;
    }
    if (t < terms.size()) {
      std::memcpy(&c, terms[t].coefficient.data(), sizeof c);
      std::memcpy(&v, u + first + terms[t].offset, sizeof v);
      even += c * v;
    }
    const Vec4 sum = even + odd;
    std::memcpy(ku + a * n + first, &sum, sizeof sum);
  }
}

// fe = k · ue for one hexahedron, k a 24 × 24 element stiffness (column-major, node-major local
// DOFs): its columns scaled by ue and summed, in six 4-wide vectors. Written out rather than left
// to Eigen, whose vector width is fixed when a file is compiled (the baseline's, in the portable
// build), while this is compiled with the kernel that calls it, for each instruction set. The
// regions' element loop and the element-by-element operator of any shape both run on it.
HAPTICSIM_KERNEL_INLINE void MultiplyElement24(const double* k, const double* ue, double* fe) {
  using stencil_detail::AddScaled4;
  using stencil_detail::Vec4;
  Vec4 sum[6] = {};
  for (int j = 0; j < 24; ++j) {
    for (int v = 0; v < 6; ++v) AddScaled4(sum[v], ue[j], k + 24 * j + 4 * v);
  }
  std::memcpy(fe, sum, sizeof sum);
}

}  // namespace hapticsim
