#pragma once

#include <Eigen/SparseCore>

#include "core/fem/hex_grid.hpp"
#include "core/fem/material.hpp"
#include "core/fem/material_field.hpp"
#include "core/fem/stiffness_operator.hpp"

namespace hapticsim {

/**
 * The global stiffness matrix K assembled element by element into an Eigen sparse matrix
 * (row-major CSR). Deliberately the textbook path, independent of the stencil kernel: it is the
 * oracle the matrix-free operator is tested against and the baseline it is benchmarked against.
 */
class AssembledStiffness final : public StiffnessOperator {
 public:
  AssembledStiffness(const HexGrid& grid, const Material& material);
  /** Over the occupied elements of `field`, each with its material's element stiffness. */
  AssembledStiffness(const HexGrid& grid, const MaterialField& field);

  void Apply(const Eigen::Ref<const Eigen::VectorXd>& u,
             Eigen::Ref<Eigen::VectorXd> ku) const override;
  Eigen::VectorXd Diagonal() const override;

  const Eigen::SparseMatrix<double, Eigen::RowMajor>& matrix() const { return matrix_; }

 private:
  Eigen::SparseMatrix<double, Eigen::RowMajor> matrix_;
};

}  // namespace hapticsim
