#include "core/fem/elementwise_stiffness.hpp"

#include <algorithm>

#include "core/fem/cpu_dispatch.hpp"
#include "core/fem/stencil_kernels.hpp"

namespace hapticsim {

ElementwiseStiffness::ElementwiseStiffness(const HexGrid& grid, const MaterialField& field)
    : StiffnessOperator(grid.num_dofs()), num_nodes_(grid.num_nodes()) {
  for (const Material& material : field.materials()) {
    stiffness_.push_back(Hex8Element::Stiffness(grid.spacing(), material));
  }
  elements_.reserve(static_cast<size_t>(field.num_occupied()));
  field.ForEachOccupied(grid, [&](const std::array<int, 8>& nodes, int material) {
    elements_.push_back({nodes, material});
  });
}

HAPTICSIM_KERNEL_CLONES
void ElementwiseStiffness::ApplyElements(const double* u, double* ku) const {
  static_assert(!Hex8Element::Matrix24::IsRowMajor, "MultiplyElement24 reads columns");
  const int n = num_nodes_;
  std::fill(ku, ku + 3 * static_cast<std::ptrdiff_t>(n), 0.0);
  double ue[24], fe[24];
  for (const Element& e : elements_) {
    // Local DOFs are node-major (3·local node + component); the grid's are component-blocked.
    for (int local = 0; local < 8; ++local) {
      for (int c = 0; c < 3; ++c) ue[3 * local + c] = u[c * n + e.nodes[local]];
    }
    MultiplyElement24(stiffness_[static_cast<size_t>(e.material)].data(), ue, fe);
    for (int local = 0; local < 8; ++local) {
      for (int c = 0; c < 3; ++c) ku[c * n + e.nodes[local]] += fe[3 * local + c];
    }
  }
}

void ElementwiseStiffness::Apply(const Eigen::Ref<const Eigen::VectorXd>& u,
                                 Eigen::Ref<Eigen::VectorXd> ku) const {
  ApplyElements(u.data(), ku.data());
}

Eigen::VectorXd ElementwiseStiffness::Diagonal() const {
  Eigen::VectorXd diagonal = Eigen::VectorXd::Zero(num_dofs());
  for (const Element& e : elements_) {
    const Hex8Element::Matrix24& k = stiffness_[static_cast<size_t>(e.material)];
    for (int local = 0; local < 8; ++local) {
      for (int c = 0; c < 3; ++c) {
        diagonal[c * num_nodes_ + e.nodes[local]] += k(3 * local + c, 3 * local + c);
      }
    }
  }
  return diagonal;
}

}  // namespace hapticsim
