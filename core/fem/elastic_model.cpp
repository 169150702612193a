#include "core/fem/elastic_model.hpp"

#include <string>

#include "core/error.hpp"
#include "core/fem/stencil_stiffness.hpp"

namespace hapticsim {

ElasticModel::ElasticModel(const HexGrid& grid, const Material& material,
                           DofConstraints constraints)
    : grid_(grid),
      material_(material),
      stiffness_(std::make_unique<StencilStiffness>(grid, material)),
      constraints_(std::move(constraints)),
      dof_mass_(grid.num_dofs()),
      free_mask_(Eigen::VectorXd::Ones(grid.num_dofs())) {
  const double h = grid.spacing();
  const double element_node_mass = material.density_kg_m3 * h * h * h / 8.0;
  const int n = grid.num_nodes();
  for (int node = 0; node < n; ++node) {
    const auto idx = grid.NodeIndices(node);
    const std::array<int, 3> counts{grid.nx(), grid.ny(), grid.nz()};
    int adjacent = 1;
    for (int axis = 0; axis < 3; ++axis) {
      const bool on_face = idx[axis] == 0 || idx[axis] == counts[axis] - 1;
      adjacent *= on_face ? 1 : 2;
    }
    for (int c = 0; c < 3; ++c) dof_mass_[grid.Dof(node, c)] = adjacent * element_node_mass;
  }
  auto constrain = [&](int dof) {
    HAPTICSIM_THROW_UNLESS(dof >= 0 && dof < grid.num_dofs(),
                           "constrained DOF " + std::to_string(dof) + " is outside the grid");
    HAPTICSIM_THROW_UNLESS(free_mask_[dof] == 1.0,
                           "DOF " + std::to_string(dof) + " is constrained twice");
    free_mask_[dof] = 0.0;
  };
  for (int dof : constraints_.fixed_dofs) constrain(dof);
  for (int dof : constraints_.driven_dofs) constrain(dof);
}

}  // namespace hapticsim
