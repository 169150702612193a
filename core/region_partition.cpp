#include "core/region_partition.hpp"

#include <algorithm>
#include <string>

#include "core/error.hpp"

namespace hapticsim {

RegionPartition::RegionPartition(const Scene& scene) : scene_(scene) {
  ValidateScene(scene);
  HAPTICSIM_THROW_UNLESS(scene.adaptivity.enabled(),
                         "asynchronous regions need adaptivity.primary_size >= 1");
  const int n = scene.mesh.nodes, last = n - 1, middle = last / 2, r = scene.adaptivity.primary_size;
  const std::array<int, 3> contact{middle, middle, 0};

  HybridMesh::Options options;
  options.nodes_per_axis = n;
  options.spacing_m = scene.mesh.edge_m / last;
  options.coarse_factor = scene.adaptivity.secondary_lod;
  for (int a = 0; a < 3; ++a) {
    options.primary_lo[a] = std::max(0, contact[a] - r);
    options.primary_hi[a] = std::min(last, contact[a] + r);
  }
  options.supports = {{0, 0, last}, {last, 0, last}, {0, last, last}, {last, last, last}};
  options.support_layers = scene.adaptivity.support_layers;
  mesh_ = std::make_unique<HybridMesh>(options);
  dof_mass_ = mesh_->DofMass(scene.material.density_kg_m3);

  std::vector<int> primary_elements, secondary_elements;
  for (int e = 0; e < static_cast<int>(mesh_->elements().size()); ++e) {
    (mesh_->elements()[e].region == kPrimaryRegion ? primary_elements : secondary_elements).push_back(e);
  }
  HAPTICSIM_THROW_UNLESS(!secondary_elements.empty(),
                         "adaptivity.primary_size = " + std::to_string(r) +
                             " leaves no secondary region");
  primary_stiffness_ = std::make_unique<ElementSetStiffness>(*mesh_, scene.material, primary_elements);
  secondary_stiffness_ =
      std::make_unique<ElementSetStiffness>(*mesh_, scene.material, secondary_elements);

  const int contact_node = mesh_->IndependentAt(contact[0], contact[1], contact[2]);
  HAPTICSIM_THROW_UNLESS(contact_node >= 0, "internal: the contact node is not independent");
  for (int c = 0; c < 3; ++c) contact_dofs_[c] = mesh_->Dof(contact_node, c);
  for (const auto& s : options.supports) {
    const int node = mesh_->IndependentAt(s[0], s[1], s[2]);
    HAPTICSIM_THROW_UNLESS(node >= 0, "internal: a support node is not independent");
    for (int c = 0; c < 3; ++c) fixed_dofs_.push_back(mesh_->Dof(node, c));
  }
  std::sort(fixed_dofs_.begin(), fixed_dofs_.end());

  const auto& mask = mesh_->region_mask();
  const int nr = mesh_->num_independent();
  auto is_fixed = [&](int dof) { return std::binary_search(fixed_dofs_.begin(), fixed_dofs_.end(), dof); };
  auto is_contact = [&](int dof) {
    return std::find(contact_dofs_.begin(), contact_dofs_.end(), dof) != contact_dofs_.end();
  };
  HAPTICSIM_THROW_UNLESS(mask[contact_node] == 1u,
                         "internal: the contact must lie inside the primary region");
  for (int c = 0; c < 3; ++c) {
    for (int node = 0; node < nr; ++node) {
      const int dof = c * nr + node;
      const bool in_primary = mask[node] & 1u, in_secondary = mask[node] & 2u;
      if (is_fixed(dof)) {
        if (in_primary) primary_fixed_.push_back(dof);
        if (in_secondary) secondary_fixed_.push_back(dof);
        continue;
      }
      if (is_contact(dof)) continue;
      if (in_primary && in_secondary) interface_dofs_.push_back(dof);
      if (in_secondary) {
        secondary_owned_.push_back(dof);
      } else if (in_primary) {
        primary_owned_.push_back(dof);
      }
    }
  }
}

int RegionPartition::num_elements(RegionIndex region) const {
  return static_cast<int>(std::count_if(mesh_->elements().begin(), mesh_->elements().end(),
                                        [&](const HybridElement& e) { return e.region == region; }));
}

int RegionPartition::num_nodes(RegionIndex region) const {
  return static_cast<int>(std::count_if(mesh_->region_mask().begin(), mesh_->region_mask().end(),
                                        [&](unsigned m) { return (m >> region) & 1u; }));
}

}  // namespace hapticsim
