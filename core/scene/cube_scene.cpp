#include "core/scene/cube_scene.hpp"

namespace hapticsim {
namespace {

HexGrid CubeGrid(const Scene& scene) {
  ValidateScene(scene);
  const int n = scene.mesh.nodes;
  return HexGrid(n, n, n, scene.mesh.edge_m / (n - 1));
}

DofConstraints CubeConstraints(const HexGrid& grid, int contact_node,
                               const std::array<int, 4>& fixed_nodes) {
  DofConstraints constraints;
  for (int node : fixed_nodes) {
    for (int c = 0; c < 3; ++c) constraints.fixed_dofs.push_back(grid.Dof(node, c));
  }
  for (int c = 0; c < 3; ++c) constraints.driven_dofs.push_back(grid.Dof(contact_node, c));
  return constraints;
}

}  // namespace

CubeScene::CubeScene(const Scene& scene)
    : scene_(scene), contact_node_(0), fixed_nodes_{}, model_([&] {
        const HexGrid grid = CubeGrid(scene);
        const LatticeIndex contact = ContactNode(scene);
        contact_node_ = grid.Node(contact[0], contact[1], contact[2]);
        const auto supports = CubeSupportNodes(scene.mesh);
        for (size_t i = 0; i < supports.size(); ++i) {
          fixed_nodes_[i] = grid.Node(supports[i][0], supports[i][1], supports[i][2]);
        }
        return ElasticModel(grid, scene.material,
                            CubeConstraints(grid, contact_node_, fixed_nodes_));
      }()) {}

}  // namespace hapticsim
