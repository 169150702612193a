#pragma once

#include <Eigen/Core>
#include <array>
#include <memory>
#include <vector>

#include "core/regions/element_set_stiffness.hpp"
#include "core/regions/hybrid_mesh.hpp"
#include "core/scene/scene.hpp"
#include "core/trial/proxy_contact.hpp"

namespace hapticsim {

/** The DOF sets one region works on. */
struct RegionDofs {
  std::vector<int> owned;  ///< integrated by this region (inner interface included), ascending
  std::vector<int> fixed;            ///< supports this region touches, held at zero
  std::vector<int> inner_interface;  ///< Γ with the next region inwards: owned, and loaded with
                                     ///< that region's forces (empty for the primary)
  std::vector<int> outer_interface;  ///< Γ with the next region outwards: prescribed from its
                                     ///< snapshots (empty for the outermost region)
};

/**
 * The scene's object (SceneObject: the paper's cube, or a geometry file's voxels of several
 * materials) split into asynchronous regions (two-way linking on a hybrid mesh):
 *
 * - region 0, the **primary region**: the coarse cells meeting the box of
 *   adaptivity.primary_size nodes around the contact, refined to the finest spacing h, only
 *   where the object is (the box clipped to it);
 * - regions 1…n, the **secondary regions** (adaptivity.secondary_regions = n): every other cell,
 *   of spacing k·h (k = adaptivity.secondary_lod), in nested shells around the primary
 *   (adaptivity.shell_cells coarse cells thick; the outermost takes the rest) — except
 *   adaptivity.support_layers coarse cells around each point or line support (the cube's corners,
 *   a held edge), refined to h too because a coarse cell at such a support is far too stiff (its
 *   stiffness is singular); and the cells the object fills only in part or with two materials
 *   (its surface, its material boundaries), refined so each coarse element is whole and of one
 *   material;
 * - an **interface Γ** between each pair of neighbouring shells: the independent nodes touched by
 *   elements of both. The outer region owns it (integrates it with the lumped mass of both sides
 *   and receives the inner region's forces); the inner region takes Γ's displacement as a
 *   prescribed boundary. Shells are nested, so a node is never shared by non-neighbours (checked).
 *
 * With k = 1 the mesh is the full-resolution grid and only the rates differ.
 */
class RegionPartition {
 public:
  /** @throws Error when the scene's adaptivity settings are invalid (see ValidateScene). */
  explicit RegionPartition(const Scene& scene);

  const Scene& scene() const { return scene_; }
  const HybridMesh& mesh() const { return *mesh_; }
  /** The object's materials, indexed by HybridElement::material. */
  const std::vector<Material>& materials() const { return materials_; }
  const Eigen::VectorXd& dof_mass() const { return dof_mass_; }
  /** Each DOF's damping rate, 1/s (HybridMesh::DofDamping). */
  const Eigen::VectorXd& dof_damping() const { return dof_damping_; }
  int num_regions() const { return static_cast<int>(stiffness_.size()); }
  /** K of the region's elements: by node stencils where they are all fine (BoxStiffness). */
  const StiffnessOperator& stiffness(RegionIndex region) const { return *stiffness_[region]; }
  const RegionDofs& dofs(RegionIndex region) const { return dofs_[region]; }
  /** Elements of `region` that touch its outer interface (the band whose forces cross it). */
  const std::vector<int>& outer_band_elements(RegionIndex region) const { return band_[region]; }

  /**
   * Whether the tool touches through a sliding proxy (SlidingContact: a stroke, or hapticsimd's
   * contact.model = "proxy"): then the
   * contact node is free, one of the primary's owned nodes, and the proxy pushes the primary's
   * nodes on the contact's face (primary_proxy_surface) instead of a node being driven.
   */
  bool proxy_contact() const { return UsesProxyContact(scene_); }
  /** The surface as the primary region's proxy touches it: the primary's own nodes (not Γ, not
   *  held) pushable, held nodes taking their share, every other node out of its reach. In the
   *  primary's state vector. Allocates. */
  ProxySurface PrimaryProxySurface() const;

  /** The contact node's x, y, z DOFs (in the primary region; prescribed unless proxy_contact). */
  const std::array<int, 3>& contact_dofs() const { return contact_dofs_; }
  /** The contact node's lattice indices and its unit inward normal (SceneObject). */
  const LatticeIndex& contact_node() const { return contact_lattice_; }
  const std::array<double, 3>& contact_normal() const { return contact_normal_; }

  int num_elements(RegionIndex region) const;
  /** Independent nodes touched by the region's elements. */
  int num_nodes(RegionIndex region) const;
  /** "primary", "secondary", or "secondary 1", "secondary 2", … with several shells. */
  std::string RegionName(RegionIndex region) const;
  /** Whether every element of the primary touches its Γ (a primary one element deep, such as
   *  primary_size 1): none of its owned nodes is out of reach of Γ's prescribed motion. */
  bool PrimaryOneElementDeep() const;

 private:
  // The contact's and supports' DOFs, and each region's owned, fixed and interface DOFs.
  void AssignDofs(const std::vector<std::array<int, 3>>& supports, int regions);
  void FindBands(const std::vector<std::vector<int>>& elements);

  Scene scene_;
  std::unique_ptr<HybridMesh> mesh_;
  std::vector<Material> materials_;
  Eigen::VectorXd dof_mass_, dof_damping_;
  LatticeIndex contact_lattice_{};
  std::array<double, 3> contact_normal_{};
  std::vector<std::unique_ptr<StiffnessOperator>> stiffness_;
  std::vector<RegionDofs> dofs_;
  std::vector<std::vector<int>> band_;
  std::array<int, 3> contact_dofs_{};
  std::vector<int> fixed_dofs_;
};

}  // namespace hapticsim
