#pragma once

#include <array>
#include <cstddef>
#include <vector>

#include "core/fem/hex_grid.hpp"
#include "core/fem/material.hpp"
#include "core/fem/stencil_kernels.hpp"
#include "core/fem/stiffness_operator.hpp"

namespace hapticsim {

/**
 * Matrix-free K·u on a structured grid of identical cube elements: a 27-point node stencil.
 *
 * On a structured grid every node sees the same element matrix, so row i of K is a fixed 3×3
 * block for each of its 27 neighbours, depending only on which of the 8 surrounding elements
 * exist. That is decided per axis by whether the node lies on the low face, inside, or on the
 * high face: 3³ = 27 node classes. The stencils of all classes are precomputed from the element
 * matrix at construction (zero couplings dropped), so Apply() is a pure streaming loop over the
 * component-blocked arrays: no index arrays, no matrix storage, rows of x vectorised.
 */
class StencilStiffness final : public StiffnessOperator {
 public:
  StencilStiffness(const HexGrid& grid, const Material& material);

  void Apply(const Eigen::Ref<const Eigen::VectorXd>& u,
             Eigen::Ref<Eigen::VectorXd> ku) const override;
  Eigen::VectorXd Diagonal() const override;

  /** Floating-point operations of one Apply() (2 per stored coupling and node). */
  double FlopsPerApply() const;

 private:
  static int AxisClass(int index, int count) {
    return index == 0 ? 0 : (index == count - 1 ? 2 : 1);
  }
  // Apply's loop over every row of the grid: the hot kernel, compiled per instruction set
  // (core/fem/cpu_dispatch.hpp).
  void ApplyRows(const double* u, double* ku) const;

  HexGrid grid_;
  std::array<NodeStencil, 27> stencils_;  // per node class
};

}  // namespace hapticsim
