#pragma once

#include <array>
#include <vector>

#include "core/fem/hex8_element.hpp"
#include "core/regions/hybrid_mesh.hpp"
#include "core/fem/stiffness_operator.hpp"

namespace hapticsim {

/**
 * Matrix-free K·u over a subset of a HybridMesh's elements (one region, or all of them), on the
 * mesh's independent DOFs: gather each element's 24 displacements through the hanging-node
 * weights, multiply by its stiffness h_e·(λA + μB) of its material, scatter back with the same
 * weights.
 *
 * Apply() writes only the DOFs the subset touches (touched_dofs()) and leaves the rest of `ku`
 * as it was, so a region can compute its own forces without touching the other's.
 */
class ElementSetStiffness final : public StiffnessOperator {
 public:
  /** `materials`: the object's, indexed by HybridElement::material. */
  ElementSetStiffness(const HybridMesh& mesh, const std::vector<Material>& materials,
                      std::vector<int> element_ids);

  void Apply(const Eigen::Ref<const Eigen::VectorXd>& u,
             Eigen::Ref<Eigen::VectorXd> ku) const override;
  Eigen::VectorXd Diagonal() const override;

  /** Independent DOFs this subset's elements reach (sorted). */
  const std::vector<int>& touched_dofs() const { return touched_dofs_; }

 private:
  // Apply's element loop: the hot kernel, compiled per instruction set (core/fem/cpu_dispatch.hpp).
  void ApplyElements(const double* u, double* ku) const;

  const HybridMesh& mesh_;
  std::vector<int> element_ids_;
  std::vector<Hex8Element::Matrix24> unit_stiffness_;  // per material: λA + μB (per metre of edge)
  std::vector<int> touched_dofs_;
  // Per element (in element_ids_ order), its 8 nodes' independent indices when none of them is
  // hanging (every gather one term of weight 1: most coarse cells), else −1 in the first: then
  // Apply goes through the mesh's gathers.
  std::vector<std::array<int, 8>> direct_nodes_;
};

}  // namespace hapticsim
