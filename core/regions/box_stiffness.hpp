#pragma once

#include <memory>
#include <vector>

#include "core/regions/element_set_stiffness.hpp"
#include "core/regions/hybrid_mesh.hpp"
#include "core/fem/material.hpp"
#include "core/fem/stencil_kernels.hpp"

namespace hapticsim {

/**
 * K·u over fine elements of a HybridMesh by node stencils on the box that bounds them: the
 * primary region (a full box), and at spacing factor 1 a secondary region (a box with the primary
 * box as its hole).
 *
 * The elements, taken alone, are cells of a structured grid over their bounding box. A node's
 * row of K depends only on which of its 8 cells are among them, so the distinct cases (inside:
 * all 8; a free face, the hole's face: 4; the hole's edges: 6; …) each get one 27-point stencil
 * (MakeNodeStencil) and each grid row is a few runs of nodes sharing one, applied vectorised
 * like StencilStiffness: 153 instead of 576 multiply-adds per inside node and no index chasing.
 * The same K·u as ElementSetStiffness over the same elements. The grid's nodes are gathered from
 * the mesh's independent DOFs (a hanging node on a face through its weights; most nodes by a
 * plain copy) and the forces scattered back the same way.
 *
 * Apply() writes only touched_dofs() — the same DOFs as ElementSetStiffness — and uses scratch
 * vectors of its own: unlike other StiffnessOperators, one thread at a time (a region's).
 */
class BoxStiffness final : public StiffnessOperator {
 public:
  /**
   * The operator for `element_ids` if they are all fine elements (each once) of one material
   * (an index into `materials`) and the box that bounds them has rows along x and y of at least
   * `min_row_nodes` nodes; nullptr otherwise (nothing built).
   */
  static std::unique_ptr<BoxStiffness> TryMake(const HybridMesh& mesh,
                                               const std::vector<Material>& materials,
                                               const std::vector<int>& element_ids,
                                               int min_row_nodes = 0);

  void Apply(const Eigen::Ref<const Eigen::VectorXd>& u,
             Eigen::Ref<Eigen::VectorXd> ku) const override;
  Eigen::VectorXd Diagonal() const override { return elements_.Diagonal(); }

  const std::vector<int>& touched_dofs() const { return elements_.touched_dofs(); }
  /** Box nodes copied in and written out directly (no weights: see direct_nodes_). */
  int direct_nodes() const { return static_cast<int>(direct_nodes_.size()); }
  /** Nodes of the bounding box per axis. */
  const std::array<int, 3>& box_nodes() const { return box_nodes_; }

 private:
  // A run of consecutive grid nodes along x sharing one stencil.
  struct Run {
    std::ptrdiff_t first = 0;  // grid node
    int length = 0;
    int stencil = 0;  // into stencils_
  };

  // Apply's gather, stencil runs and scatter: the hot kernel, compiled per instruction set
  // (core/fem/cpu_dispatch.hpp).
  void ApplyOnBox(const double* u, double* ku) const;

  BoxStiffness(const HybridMesh& mesh, const std::vector<Material>& materials, int material,
               std::vector<int> element_ids,
               const std::array<int, 3>& box_nodes, std::vector<int> box_mesh_nodes,
               const std::vector<unsigned>& cell_masks);

  const HybridMesh& mesh_;
  ElementSetStiffness elements_;  // the same operator element by element: its DOFs, its diagonal
  std::array<int, 3> box_nodes_;
  std::vector<NodeStencil> stencils_;  // one per distinct set of cells around a node
  std::vector<Run> runs_;              // every grid node among the elements, row by row
  std::vector<int> gather_start_;      // per grid node, into gather_terms_
  std::vector<GatherTerm> gather_terms_;
  // Most grid nodes (the inside, most of the faces) are an independent node that no other grid
  // node leans on: copied in and their forces written out, with no weights and no zeroing. The
  // others (hanging nodes on faces and the nodes they lean on) are gathered and scattered by
  // their weights, onto forces zeroed first.
  struct DirectNode {
    int box = 0;
    int independent = 0;
  };
  std::vector<DirectNode> direct_nodes_;
  std::vector<int> weighted_nodes_;  // grid nodes
  std::vector<int> zeroed_dofs_;     // touched_dofs() that no direct node writes
  mutable Eigen::VectorXd u_box_, ku_box_;
};

}  // namespace hapticsim
