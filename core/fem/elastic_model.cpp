#include "core/fem/elastic_model.hpp"

#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/fem/elementwise_stiffness.hpp"
#include "core/fem/stencil_stiffness.hpp"

namespace hapticsim {

ElasticModel::ElasticModel(const HexGrid& grid, const Material& material,
                           DofConstraints constraints)
    : ElasticModel(grid, MaterialField(grid, material), std::move(constraints)) {}

ElasticModel::ElasticModel(const HexGrid& grid, MaterialField field, DofConstraints constraints)
    : grid_(grid),
      field_(std::move(field)),
      constraints_(std::move(constraints)),
      dof_mass_(Eigen::VectorXd::Zero(grid.num_dofs())),
      dof_damping_(Eigen::VectorXd::Zero(grid.num_dofs())),
      free_mask_(Eigen::VectorXd::Ones(grid.num_dofs())) {
  field_.CheckFits(grid);
  const std::vector<bool> used = field_.UsedMaterials();
  damping_per_s_ = -1;
  for (size_t i = 0; i < used.size(); ++i) {
    if (!used[i]) continue;
    const double d = field_.materials()[i].damping_per_s;
    if (damping_per_s_ < 0) damping_per_s_ = d;
    if (d != damping_per_s_) uniform_damping_ = false;
  }
  if (const int uniform = field_.uniform_material(); uniform >= 0) {
    stiffness_ =
        std::make_unique<StencilStiffness>(grid, field_.materials()[static_cast<size_t>(uniform)]);
  } else {
    stiffness_ = std::make_unique<ElementwiseStiffness>(grid, field_);
  }
  LumpMassAndDamping();
  Constrain();
}

double ElasticModel::damping_per_s() const {
  HAPTICSIM_THROW_UNLESS(uniform_damping_,
                         "the materials' damping differs: the object has no one damping rate "
                         "(use the per-DOF dof_damping)");
  return damping_per_s_;
}

void ElasticModel::LumpMassAndDamping() {
  // Counted per material, then multiplied: a node's k equal shares as k·share, as exactly as the
  // cube always had it (a sum of k equal terms can round differently).
  const double h = grid_.spacing();
  const int n = grid_.num_nodes();
  const size_t materials = field_.materials().size();
  std::vector<std::uint8_t> count(static_cast<size_t>(n) * materials, 0);  // at most 8
  field_.ForEachOccupied(grid_, [&](const std::array<int, 8>& nodes, int material) {
    for (int node : nodes)
      ++count[static_cast<size_t>(node) * materials + static_cast<size_t>(material)];
  });
  for (int node = 0; node < n; ++node) {
    double mass = 0, damping = 0;  // Σ m_e and Σ d_e·m_e over the node's elements
    double one_d = -1;             // the d all its elements share; NaN when they differ
    for (size_t m = 0; m < materials; ++m) {
      const int k = count[static_cast<size_t>(node) * materials + m];
      if (k == 0) continue;
      const Material& material = field_.materials()[m];
      const double share = material.density_kg_m3 * h * h * h / 8.0;
      mass += k * share;
      damping += material.damping_per_s * (k * share);
      one_d = (one_d < 0 || one_d == material.damping_per_s) ? material.damping_per_s : NAN;
    }
    // Elements that damp alike give their d itself: c/m would round it.
    double d = 0;  // off the object
    if (one_d >= 0) {
      d = one_d;
    } else if (mass > 0) {
      d = damping / mass;
    }
    for (int c = 0; c < 3; ++c) {
      dof_mass_[grid_.Dof(node, c)] = mass;
      dof_damping_[grid_.Dof(node, c)] = d;
    }
  }
}

void ElasticModel::Constrain() {
  auto constrain = [&](int dof) {
    HAPTICSIM_THROW_UNLESS(dof >= 0 && dof < grid_.num_dofs(),
                           "constrained DOF " + std::to_string(dof) + " is outside the grid");
    HAPTICSIM_THROW_UNLESS(free_mask_[dof] == 1.0,
                           "DOF " + std::to_string(dof) + " is constrained twice");
    HAPTICSIM_THROW_UNLESS(dof_mass_[dof] > 0.0, "constrained DOF " + std::to_string(dof) +
                                                     " is off the object: no element touches it");
    free_mask_[dof] = 0.0;
  };
  for (int dof : constraints_.fixed_dofs) constrain(dof);
  for (int dof : constraints_.driven_dofs) constrain(dof);
  // Off the object: no mass, no stiffness, held where it is (after the checks above, so a
  // constraint there is not counted twice).
  for (int dof = 0; dof < grid_.num_dofs(); ++dof) {
    if (dof_mass_[dof] == 0.0) free_mask_[dof] = 0.0;
  }
}

}  // namespace hapticsim
