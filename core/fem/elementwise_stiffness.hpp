#pragma once

#include <array>
#include <cstddef>
#include <map>
#include <vector>

#include "core/fem/hex8_element.hpp"
#include "core/fem/hex_grid.hpp"
#include "core/fem/material_field.hpp"
#include "core/fem/stencil_kernels.hpp"
#include "core/fem/stiffness_operator.hpp"

namespace hapticsim {

/**
 * K·u matrix-free over the occupied elements of a MaterialField: an object of any shape on the
 * lattice, each element with its own material. Two kernels, one chosen at construction:
 *
 * - Node stencils (the uniform cube's trick, StencilStiffness, on a masked grid). Every element
 *   is a cube of the grid's spacing h, so a node's row of K depends only on the materials of the
 *   8 cells around it (empty or outside the grid: absent). One stencil per distinct 8-tuple, and
 *   Apply() a loop over each row's segments along x: runs of 4 or more consecutive nodes sharing
 *   a stencil (ApplyStencilRun, vectorised), and between them, where the stencil changes every
 *   node or two (faces, material boundaries), windows of 4 nodes with their stencils merged lane
 *   by lane (ApplyLaneStencil, deduplicated by the 4 stencils). Nodes no occupied element touches
 *   have an empty stencil, which writes ku = 0.
 * - Elements: one 24 × 24 matrix per material; per element, gather its 24 displacements,
 *   multiply (the regions' vector kernel, core/fem/stencil_kernels.hpp), add back. ~4× the
 *   stencil's arithmetic, but no per-node coefficients to stream: it wins when the field is so
 *   mixed that the merged windows are many and seldom repeat (a random field).
 *
 * kAuto estimates both (ChooseKernel) and takes the cheaper. StencilStiffness stays the
 * operator of the uniform, full cube; this one is for everything else, and is tested against
 * AssembledStiffness built from the same field with either kernel.
 *
 * Thread-safety: Apply() is const and keeps no scratch; any thread may call it.
 */
class ElementwiseStiffness final : public StiffnessOperator {
 public:
  enum class Kernel { kAuto, kNodeStencils, kElements };

  /** @throws Error when `field` was not made for `grid` (MaterialField::CheckFits). */
  ElementwiseStiffness(const HexGrid& grid, const MaterialField& field,
                       Kernel kernel = Kernel::kAuto);

  /** Never allocates. */
  void Apply(const Eigen::Ref<const Eigen::VectorXd>& u,
             Eigen::Ref<Eigen::VectorXd> ku) const override;
  Eigen::VectorXd Diagonal() const override;

  int num_elements() const { return static_cast<int>(elements_.size()); }
  /** The kernel Apply() runs (never kAuto). */
  Kernel kernel() const { return kernel_; }
  /** Distinct node stencils and merged 4-node windows (0 when the element kernel runs). */
  int num_stencils() const { return static_cast<int>(stencils_.size()); }
  int num_lane_stencils() const { return static_cast<int>(lane_stencils_.size()); }

 private:
  struct Element {
    std::array<int, 8> nodes;
    int material;  // index into stiffness_
  };
  // `length` consecutive nodes along x from `first`: with node stencil `stencil` (lanes false),
  // or the 4 nodes of lane stencil `stencil` (lanes true, length 4).
  struct Segment {
    std::ptrdiff_t first;
    int length;
    int stencil;
    bool lanes;
  };
  struct NodeClasses;  // which 8-tuple of cells each node has (defined in the .cpp)
  using LaneIndex = std::map<std::array<int, 4>, int>;

  NodeClasses ClassifyNodes(const HexGrid& grid, const MaterialField& field) const;
  void BuildStencils(const HexGrid& grid, const NodeClasses& classes);
  void SegmentRow(std::ptrdiff_t row, int nx, const int* class_of, LaneIndex* lane_index);
  void AddWindow(std::ptrdiff_t row, int nx, const int* class_of, int from, int to,
                 LaneIndex* lane_index);
  Kernel ChooseKernel(const NodeClasses& classes) const;
  // Apply's loops, compiled per instruction set (core/fem/cpu_dispatch.hpp).
  void ApplyElements(const double* u, double* ku) const;
  void ApplySegments(const double* u, double* ku) const;

  int num_nodes_;
  Kernel kernel_;
  std::vector<Hex8Element::Matrix24> stiffness_;  // per material, N/m (column-major)
  std::vector<Element> elements_;
  // The node-stencil kernel (empty when the element kernel runs):
  std::vector<NodeStencil> stencils_;       // per distinct 8-tuple of cells
  std::vector<LaneStencil> lane_stencils_;  // per distinct 4 consecutive stencils merged
  std::vector<Segment> segments_;           // every node of the grid, in node order
};

}  // namespace hapticsim
