#pragma once

#include <array>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "core/element_set_stiffness.hpp"
#include "core/hybrid_mesh.hpp"
#include "core/scene.hpp"

namespace hapticsim {

/**
 * The paper's cube split into asynchronous regions (two-way linking on a hybrid mesh):
 *
 * - the **primary region**: the coarse cells meeting the box of adaptivity.primary_size nodes
 *   around the contact, refined to the finest spacing h;
 * - the **secondary region**: every other cell, of spacing k·h (k = adaptivity.secondary_lod),
 *   except adaptivity.support_layers coarse cells around each fixed corner, refined to h too
 *   because a coarse cell at a point support is far too stiff (its stiffness is singular);
 * - the **interface Γ**: the independent nodes touched by elements of both regions. The
 *   secondary owns Γ (it integrates Γ with the whole lumped mass of both sides and receives the
 *   primary's interface forces); the primary takes Γ's displacement as a prescribed boundary.
 *
 * With k = 1 the mesh is the full-resolution grid and only the rates differ.
 */
class RegionPartition {
 public:
  /** @throws Error when the scene's adaptivity settings are invalid (see ValidateScene). */
  explicit RegionPartition(const Scene& scene);

  const Scene& scene() const { return scene_; }
  const HybridMesh& mesh() const { return *mesh_; }
  const Eigen::VectorXd& dof_mass() const { return dof_mass_; }
  const ElementSetStiffness& primary_stiffness() const { return *primary_stiffness_; }
  const ElementSetStiffness& secondary_stiffness() const { return *secondary_stiffness_; }

  /** The contact node's x, y, z DOFs. */
  const std::array<int, 3>& contact_dofs() const { return contact_dofs_; }
  const std::vector<int>& fixed_dofs() const { return fixed_dofs_; }
  /** Γ: DOFs touched by both regions (supports and contact excluded), sorted. */
  const std::vector<int>& interface_dofs() const { return interface_dofs_; }
  const std::vector<int>& primary_owned() const { return primary_owned_; }
  const std::vector<int>& secondary_owned() const { return secondary_owned_; }
  /** Fixed DOFs each region touches (held at zero by that region). */
  const std::vector<int>& primary_fixed() const { return primary_fixed_; }
  const std::vector<int>& secondary_fixed() const { return secondary_fixed_; }

  int num_elements(RegionIndex region) const;
  /** Independent nodes touched by the region's elements. */
  int num_nodes(RegionIndex region) const;

 private:
  Scene scene_;
  std::unique_ptr<HybridMesh> mesh_;
  Eigen::VectorXd dof_mass_;
  std::unique_ptr<ElementSetStiffness> primary_stiffness_, secondary_stiffness_;
  std::array<int, 3> contact_dofs_{};
  std::vector<int> fixed_dofs_, interface_dofs_, primary_owned_, secondary_owned_;
  std::vector<int> primary_fixed_, secondary_fixed_;
};

}  // namespace hapticsim
