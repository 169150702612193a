#pragma once

#include <Eigen/Core>
#include <vector>

#include "core/regions/hybrid_mesh.hpp"

namespace hapticsim::testing {

/** Every element of the mesh, by index. */
inline std::vector<int> AllElements(const HybridMesh& mesh) {
  std::vector<int> ids(mesh.elements().size());
  for (size_t i = 0; i < ids.size(); ++i) ids[i] = static_cast<int>(i);
  return ids;
}

/** The affine field u = A·x + b (x in m) on the mesh's independent nodes. */
inline Eigen::VectorXd AffineField(const HybridMesh& mesh, const Eigen::Matrix3d& a,
                                   const Eigen::Vector3d& b) {
  Eigen::VectorXd u(mesh.num_dofs());
  const double h = mesh.options().spacing_m;
  for (int r = 0; r < mesh.num_independent(); ++r) {
    const auto& p = mesh.LatticeOf(r);
    const Eigen::Vector3d value = a * (h * Eigen::Vector3d(p[0], p[1], p[2])) + b;
    for (int c = 0; c < 3; ++c) u[mesh.Dof(r, c)] = value[c];
  }
  return u;
}

}  // namespace hapticsim::testing
