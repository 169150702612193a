#pragma once

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "core/fem/hex_grid.hpp"
#include "core/fem/material.hpp"
#include "core/fem/material_field.hpp"
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
 * Lumped mass: every occupied element gives ρ_e·h³/8 to each of its 8 nodes, so a node's mass
 * is the sum over the occupied elements around it. A node no occupied element touches (outside
 * an object of another shape than the grid's box) has neither mass nor stiffness: it is held
 * like a fixed one (free_mask 0) and never moves.
 */
class ElasticModel {
 public:
  /** The whole grid of one material (the paper's cube): the stencil operator. */
  ElasticModel(const HexGrid& grid, const Material& material, DofConstraints constraints);
  /**
   * Any shape and materials on the grid: the element-by-element operator, unless the field is
   * one material in every element (then as above, to the bit).
   * @throws Error when the field was made for another grid, a constrained DOF is out of range,
   *         listed twice or off the object, or when the damping of the materials used differs
   *         (C = d·M takes one d for the whole object).
   */
  ElasticModel(const HexGrid& grid, MaterialField field, DofConstraints constraints);

  const HexGrid& grid() const { return grid_; }
  const MaterialField& field() const { return field_; }
  /** d in C = d·M, 1/s: the same for every material the field uses. */
  double damping_per_s() const { return damping_per_s_; }
  const StiffnessOperator& stiffness() const { return *stiffness_; }
  const DofConstraints& constraints() const { return constraints_; }
  /** Lumped mass of every DOF, kg (component-blocked like the displacements); 0 off the object. */
  const Eigen::VectorXd& dof_mass() const { return dof_mass_; }
  /** 1 for a free DOF, 0 for a fixed or driven one or one off the object. */
  const Eigen::VectorXd& free_mask() const { return free_mask_; }

 private:
  void LumpMass();
  void Constrain();

  HexGrid grid_;
  MaterialField field_;
  double damping_per_s_ = 0;
  std::unique_ptr<StiffnessOperator> stiffness_;
  DofConstraints constraints_;
  Eigen::VectorXd dof_mass_;
  Eigen::VectorXd free_mask_;
};

}  // namespace hapticsim
