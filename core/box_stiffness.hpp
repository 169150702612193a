#pragma once

#include <memory>
#include <vector>

#include "core/element_set_stiffness.hpp"
#include "core/hybrid_mesh.hpp"
#include "core/stencil_stiffness.hpp"

namespace hapticsim {

/**
 * K·u over a box of fine elements of a HybridMesh — a primary region — by the 27-point stencil.
 *
 * The box's elements, taken alone, are exactly a HexGrid of the box's size whose faces are free:
 * a node on the box's face has only the elements inside it, as a node on the cube's face has.
 * So StencilStiffness on that grid gives the same K·u as ElementSetStiffness over the same
 * elements, with 153 instead of 576 multiply-adds per node and no index chasing (3.6–5× faster
 * per node, docs/benchmarks.md). The box's nodes are gathered from the mesh's independent DOFs
 * (a hanging node on its face through its weights) and its forces scattered back the same way.
 *
 * Apply() writes only touched_dofs() — the same DOFs as ElementSetStiffness — and uses scratch
 * vectors of its own: unlike other StiffnessOperators, one thread at a time (a region's).
 */
class BoxStiffness final : public StiffnessOperator {
 public:
  /**
   * The operator for `element_ids` if they are exactly the fine elements of an axis-aligned box
   * (every one of them, nothing else) whose rows along x and y have at least `min_row_nodes`
   * nodes; nullptr otherwise (nothing built).
   */
  static std::unique_ptr<BoxStiffness> TryMake(const HybridMesh& mesh, const Material& material,
                                               const std::vector<int>& element_ids,
                                               int min_row_nodes = 0);

  void Apply(const Eigen::Ref<const Eigen::VectorXd>& u,
             Eigen::Ref<Eigen::VectorXd> ku) const override;
  Eigen::VectorXd Diagonal() const override { return elements_.Diagonal(); }

  const std::vector<int>& touched_dofs() const { return elements_.touched_dofs(); }
  /** Nodes of the box per axis. */
  const std::array<int, 3>& box_nodes() const { return box_nodes_; }

 private:
  BoxStiffness(const HybridMesh& mesh, const Material& material, std::vector<int> element_ids,
               const std::array<int, 3>& box_nodes, std::vector<int> box_mesh_nodes);

  const HybridMesh& mesh_;
  ElementSetStiffness elements_;  // the same operator element by element: its DOFs, its diagonal
  std::array<int, 3> box_nodes_;
  StencilStiffness stencil_;
  std::vector<int> gather_start_;  // per box node, into gather_terms_
  std::vector<GatherTerm> gather_terms_;
  mutable Eigen::VectorXd u_box_, ku_box_;
};

}  // namespace hapticsim
