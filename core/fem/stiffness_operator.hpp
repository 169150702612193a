#pragma once

#include <Eigen/Core>

namespace hapticsim {

/**
 * y = K·u for a linear-elastic model, in the component-blocked DOF layout of HexGrid.
 * Implementations: StencilStiffness (matrix-free, the one the simulation runs) and
 * AssembledStiffness (Eigen sparse matrix, the test oracle and benchmark baseline).
 *
 * Thread-safety: Apply() is const and touches no shared mutable state; any thread may call it —
 * except BoxStiffness, which keeps scratch vectors: one thread at a time (its region's).
 */
class StiffnessOperator {
 public:
  virtual ~StiffnessOperator() = default;

  int num_dofs() const { return num_dofs_; }

  /**
   * Computes ku = K·u. Never allocates.
   * @pre u.size() == ku.size() == num_dofs(), and u, ku do not alias.
   */
  virtual void Apply(const Eigen::Ref<const Eigen::VectorXd>& u,
                     Eigen::Ref<Eigen::VectorXd> ku) const = 0;

  /** The diagonal of K (for Jacobi preconditioning), N/m. */
  virtual Eigen::VectorXd Diagonal() const = 0;

 protected:
  explicit StiffnessOperator(int num_dofs) : num_dofs_(num_dofs) {}

 private:
  int num_dofs_;
};

}  // namespace hapticsim
