#include "core/fem/assembled_stiffness.hpp"

#include <array>
#include <vector>

#include "core/fem/hex8_element.hpp"

namespace hapticsim {

AssembledStiffness::AssembledStiffness(const HexGrid& grid, const Material& material)
    : AssembledStiffness(grid, MaterialField(grid, material)) {}

AssembledStiffness::AssembledStiffness(const HexGrid& grid, const MaterialField& field)
    : StiffnessOperator(grid.num_dofs()), matrix_(grid.num_dofs(), grid.num_dofs()) {
  std::vector<Hex8Element::Matrix24> ke;
  for (const Material& material : field.materials()) {
    ke.push_back(Hex8Element::Stiffness(grid.spacing(), material));
  }
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(static_cast<size_t>(field.num_occupied()) * 24 * 24);
  field.ForEachOccupied(grid, [&](const std::array<int, 8>& nodes, int material) {
    const Hex8Element::Matrix24& k = ke[static_cast<size_t>(material)];
    for (int i = 0; i < 24; ++i) {
      const int row = grid.Dof(nodes[i / 3], i % 3);
      for (int j = 0; j < 24; ++j) {
        triplets.emplace_back(row, grid.Dof(nodes[j / 3], j % 3), k(i, j));
      }
    }
  });
  matrix_.setFromTriplets(triplets.begin(), triplets.end());
  matrix_.makeCompressed();
}

void AssembledStiffness::Apply(const Eigen::Ref<const Eigen::VectorXd>& u,
                               Eigen::Ref<Eigen::VectorXd> ku) const {
  ku.noalias() = matrix_ * u;
}

Eigen::VectorXd AssembledStiffness::Diagonal() const { return matrix_.diagonal(); }

}  // namespace hapticsim
