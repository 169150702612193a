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
 *   M ü + C u̇ + K u = f,  C = Σ_e d_e·M_e,
 * with the matrix-free stiffness K, the lumped (diagonal) mass M, and the prescribed DOFs.
 * Each element's material damps its own mass (d_e, 1/s); with the lumped mass C is diagonal
 * too, c_i = Σ_e d_e·m_{e,i}, so every DOF has its own rate d_i = c_i/m_i (dof_damping).
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
   * @throws Error when the field was made for another grid, or a constrained DOF is out of
   *         range, listed twice or off the object.
   */
  ElasticModel(const HexGrid& grid, MaterialField field, DofConstraints constraints);

  const HexGrid& grid() const { return grid_; }
  const MaterialField& field() const { return field_; }
  /** Whether every material the field uses has the same damping d (then C = d·M). */
  bool uniform_damping() const { return uniform_damping_; }
  /**
   * d in C = d·M, 1/s, for callers that take one rate for the whole object.
   * @throws Error unless uniform_damping(): an object of several dampings has only dof_damping.
   */
  double damping_per_s() const;
  /**
   * d_i = c_i/m_i of every DOF, 1/s (component-blocked; 0 off the object): the mass-weighted
   * damping of the elements around its node. A node whose elements all damp alike gets exactly
   * their d (no quotient that could round), so a uniform object has d everywhere, to the bit.
   */
  const Eigen::VectorXd& dof_damping() const { return dof_damping_; }
  const StiffnessOperator& stiffness() const { return *stiffness_; }
  const DofConstraints& constraints() const { return constraints_; }
  /** Lumped mass of every DOF, kg (component-blocked like the displacements); 0 off the object. */
  const Eigen::VectorXd& dof_mass() const { return dof_mass_; }
  /** 1 for a free DOF, 0 for a fixed or driven one or one off the object. */
  const Eigen::VectorXd& free_mask() const { return free_mask_; }

 private:
  void LumpMassAndDamping();
  void Constrain();

  HexGrid grid_;
  MaterialField field_;
  bool uniform_damping_ = true;
  double damping_per_s_ = 0;  // the one d when uniform_damping_
  std::unique_ptr<StiffnessOperator> stiffness_;
  DofConstraints constraints_;
  Eigen::VectorXd dof_mass_;
  Eigen::VectorXd dof_damping_;
  Eigen::VectorXd free_mask_;
};

}  // namespace hapticsim
