#pragma once

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "core/fem/hex_grid.hpp"
#include "core/fem/material.hpp"
#include "core/fem/stiffness_operator.hpp"

namespace hapticsim {

/** Degrees of freedom whose displacement is prescribed rather than solved for. */
struct DofConstraints {
  std::vector<int> fixed_dofs;   ///< held at zero displacement (supports)
  std::vector<int> driven_dofs;  ///< set from the device input every step (the contact)
};

/**
 * A linear-elastic body on a structured hexahedral grid, ready to time-step:
 *   M ü + C u̇ + K u = f,  C = d·M,
 * with the matrix-free stiffness K, the lumped (diagonal) mass M, and the prescribed DOFs.
 *
 * Lumped mass: every element gives ρ·h³/8 to each of its 8 nodes, so a node's mass is
 * ρ·h³·(number of adjacent elements)/8.
 */
class ElasticModel {
 public:
  /** @throws Error when a constrained DOF index is out of range or listed twice. */
  ElasticModel(const HexGrid& grid, const Material& material, DofConstraints constraints);

  const HexGrid& grid() const { return grid_; }
  const Material& material() const { return material_; }
  const StiffnessOperator& stiffness() const { return *stiffness_; }
  const DofConstraints& constraints() const { return constraints_; }
  /** Lumped mass of every DOF, kg (component-blocked like the displacements). */
  const Eigen::VectorXd& dof_mass() const { return dof_mass_; }
  /** 1 for a free DOF, 0 for a fixed or driven one. */
  const Eigen::VectorXd& free_mask() const { return free_mask_; }

 private:
  HexGrid grid_;
  Material material_;
  std::unique_ptr<StiffnessOperator> stiffness_;
  DofConstraints constraints_;
  Eigen::VectorXd dof_mass_;
  Eigen::VectorXd free_mask_;
};

}  // namespace hapticsim
