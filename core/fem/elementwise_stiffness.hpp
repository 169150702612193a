#pragma once

#include <array>
#include <vector>

#include "core/fem/hex8_element.hpp"
#include "core/fem/hex_grid.hpp"
#include "core/fem/material_field.hpp"
#include "core/fem/stiffness_operator.hpp"

namespace hapticsim {

/**
 * K·u matrix-free, element by element, over the occupied elements of a MaterialField: an object
 * of any shape on the lattice, each element with its own material.
 *
 * Every element is a cube of the grid's spacing h, so an element's stiffness depends only on its
 * material: the operator keeps one 24 × 24 matrix per material and, per element, its 8 nodes and
 * which matrix; it gathers the element's 24 displacements, multiplies (the regions' vector kernel,
 * core/fem/stencil_kernels.hpp) and adds the result back. Nodes no occupied element touches get
 * no stiffness (their rows of K are zero).
 *
 * StencilStiffness stays the operator of the uniform, full cube (its kernels are several times
 * faster there; docs/benchmarks.md); this one is for everything else, and is tested against
 * AssembledStiffness built from the same field.
 */
class ElementwiseStiffness final : public StiffnessOperator {
 public:
  ElementwiseStiffness(const HexGrid& grid, const MaterialField& field);

  /** Never allocates. */
  void Apply(const Eigen::Ref<const Eigen::VectorXd>& u,
             Eigen::Ref<Eigen::VectorXd> ku) const override;
  Eigen::VectorXd Diagonal() const override;

  int num_elements() const { return static_cast<int>(elements_.size()); }

 private:
  struct Element {
    std::array<int, 8> nodes;
    int material;  // index into stiffness_
  };
  // Apply's loop, compiled per instruction set (core/fem/cpu_dispatch.hpp).
  void ApplyElements(const double* u, double* ku) const;

  int num_nodes_;
  std::vector<Hex8Element::Matrix24> stiffness_;  // per material, N/m (column-major)
  std::vector<Element> elements_;
};

}  // namespace hapticsim
