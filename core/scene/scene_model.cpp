#include "core/scene/scene_model.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/error.hpp"
#include "core/fem/rigid_modes.hpp"
#include "core/scene/label_materials.hpp"
#include "core/scene/support_regions.hpp"

namespace hapticsim {
namespace {

// The object before it becomes a model: its lattice, materials, and where it sits.
struct ObjectLayout {
  HexGrid grid;
  MaterialField field;
  std::array<double, 3> origin_m{};
  const LabelVolume* labels = nullptr;
};

ObjectLayout CubeLayout(const Scene& scene) {
  const int n = scene.mesh.nodes;
  const HexGrid grid(n, n, n, scene.mesh.edge_m / (n - 1));
  const Material& material =
      scene.materials.empty() ? scene.material : scene.materials.front().material;
  return ObjectLayout{grid, MaterialField(grid, material), {}, nullptr};
}

ObjectLayout VolumeLayout(const Scene& scene) {
  HAPTICSIM_THROW_UNLESS(scene.loaded_geometry && scene.loaded_geometry->source == scene.geometry,
                         "geometry.file = " + scene.geometry.file +
                             " has not been read at these geometry settings: load the scene "
                             "with LoadSceneFile, or call LoadSceneGeometry after changing it");
  const LabelVolume& voxels = scene.loaded_geometry->voxels;
  const HexGrid grid(voxels.voxels[0] + 1, voxels.voxels[1] + 1, voxels.voxels[2] + 1,
                     voxels.spacing_m);
  const LabelMaterialIndex index = IndexLabelMaterials(scene);
  std::vector<std::int16_t> element_material(voxels.num_voxels(), MaterialField::kEmpty);
  for (std::size_t e = 0; e < element_material.size(); ++e) {
    const int label = voxels.labels[e];
    if (label == 0) continue;
    const int material = index.index_of_label[static_cast<std::size_t>(label)];
    HAPTICSIM_THROW_UNLESS(material >= 0, "label " + std::to_string(label) +
                                              " of the geometry has no [[material]] table");
    element_material[e] = static_cast<std::int16_t>(material);
  }
  return ObjectLayout{grid, MaterialField(grid, index.materials, std::move(element_material)),
                      voxels.origin_m, &voxels};
}

std::vector<int> FixedNodes(const Scene& scene, const ObjectLayout& object) {
  if (!scene.supports.empty()) {
    return SelectSupportNodes(
        scene.supports, ObjectLattice{object.grid, object.field, object.origin_m, object.labels});
  }
  HAPTICSIM_THROW_UNLESS(!scene.geometry.from_file(),
                         "a scene with geometry.file needs [[support]] tables saying which "
                         "nodes are held: by label (label = 3), box (box_min = [x, y, z], "
                         "box_max = [x, y, z], m) or plane (plane_point, plane_normal)");
  std::vector<int> nodes;
  for (const LatticeIndex& at : CubeSupportNodes(scene.mesh)) {
    nodes.push_back(object.grid.Node(at[0], at[1], at[2]));
  }
  return nodes;
}

// The front-most node of the lattice column nearest the object's middle in x and y.
int DefaultContactOnVolume(const HexGrid& grid, const MaterialField& field) {
  const std::vector<bool> active = field.ActiveNodes(grid);
  const double cx = 0.5 * (grid.nx() - 1), cy = 0.5 * (grid.ny() - 1);
  int best = -1;
  double best_distance = std::numeric_limits<double>::infinity();
  for (int iy = 0; iy < grid.ny(); ++iy) {
    for (int ix = 0; ix < grid.nx(); ++ix) {
      for (int iz = 0; iz < grid.nz(); ++iz) {
        const int node = grid.Node(ix, iy, iz);
        if (!active[static_cast<std::size_t>(node)]) continue;
        // Ties go to the lower index, like the cube's middle node with an even count.
        const double distance = std::hypot(ix - cx, iy - cy);
        if (distance < best_distance - 1e-12) {
          best = node;
          best_distance = distance;
        }
        break;  // the column's front-most node only
      }
    }
  }
  return best;
}

int ContactOf(const Scene& scene, const ObjectLayout& object) {
  const HexGrid& grid = object.grid;
  if (!scene.geometry.from_file()) {
    const LatticeIndex at = ContactNode(scene);
    return grid.Node(at[0], at[1], at[2]);
  }
  if (!scene.input.contact_node) return DefaultContactOnVolume(grid, object.field);
  const LatticeIndex at = *scene.input.contact_node;
  const std::string name = "input.contact_node = " + GetSceneValue(scene, "input.contact_node");
  HAPTICSIM_THROW_UNLESS(at[0] >= 0 && at[1] >= 0 && at[2] >= 0 && at[0] < grid.nx() &&
                             at[1] < grid.ny() && at[2] < grid.nz(),
                         name + " is outside the geometry's lattice of " +
                             std::to_string(grid.nx()) + " × " + std::to_string(grid.ny()) + " × " +
                             std::to_string(grid.nz()) + " nodes");
  const int node = grid.Node(at[0], at[1], at[2]);
  HAPTICSIM_THROW_UNLESS(IsObjectSurfaceNode(grid, object.field, node),
                         name +
                             " is not on the object's surface: choose a node of the object "
                             "next to an empty voxel");
  return node;
}

std::array<double, 3> NormalOf(const Scene& scene, const ObjectLayout& object, int node) {
  if (!scene.geometry.from_file()) return InwardNormal(scene.mesh, ContactNode(scene));
  const std::array<double, 3> normal = ObjectInwardNormal(object.grid, object.field, node);
  HAPTICSIM_THROW_UNLESS(normal != (std::array<double, 3>{}),
                         "the contact node has no inward direction (the object lies evenly "
                         "around it): choose another input.contact_node");
  return normal;
}

DofConstraints Constraints(const HexGrid& grid, const std::vector<int>& fixed, int contact) {
  DofConstraints constraints;
  for (int node : fixed) {
    for (int c = 0; c < 3; ++c) constraints.fixed_dofs.push_back(grid.Dof(node, c));
  }
  for (int c = 0; c < 3; ++c) constraints.driven_dofs.push_back(grid.Dof(contact, c));
  return constraints;
}

}  // namespace

SceneObject DescribeSceneObject(const Scene& scene) {
  ValidateScene(scene);
  ObjectLayout object = scene.geometry.from_file() ? VolumeLayout(scene) : CubeLayout(scene);
  const std::vector<int> fixed = FixedNodes(scene, object);
  const int contact = ContactOf(scene, object);
  HAPTICSIM_THROW_UNLESS(!std::binary_search(fixed.begin(), fixed.end(), contact),
                         "the contact node is held by a support: the contact node must be free "
                         "to move (move input.contact_node or the support)");
  const std::array<double, 3> normal = NormalOf(scene, object, contact);
  const std::string rigid = RigidBodyModeProblem(object.grid, object.field, fixed);
  HAPTICSIM_THROW_UNLESS(rigid.empty(), "the supports do not hold the object: " + rigid);
  return SceneObject{object.grid, std::move(object.field), fixed, contact, normal, object.origin_m};
}

LatticeIndex SceneContactNode(const Scene& scene) {
  if (!scene.geometry.from_file() || scene.input.contact_node) return ContactNode(scene);
  const SceneObject object = DescribeSceneObject(scene);
  return object.grid.NodeIndices(object.contact_node);
}

std::string ContactNodeProblemOn(const Scene& scene, const LatticeIndex& node) {
  // The cube's rule, and on the cube with [[support]] tables, whether they hold the node.
  if (!scene.geometry.from_file()) {
    const std::string problem = ContactNodeProblem(scene.mesh, node, scene.supports.empty());
    if (!problem.empty() || scene.supports.empty()) return problem;
  }
  Scene at = scene;
  at.input.contact_node = node;
  try {
    (void)DescribeSceneObject(at);
  } catch (const Error& e) {
    // Worded to follow the node, as ContactNodeProblem's are ("node (…) is …").
    const std::string named =
        "input.contact_node = " + GetSceneValue(at, "input.contact_node") + " ";
    const std::string what = e.what();
    return what.rfind(named, 0) == 0 ? what.substr(named.size()) : "cannot be the contact: " + what;
  }
  return "";
}

SceneModel::SceneModel(const Scene& scene) : SceneModel(scene, DescribeSceneObject(scene)) {}

SceneModel::SceneModel(const Scene& scene, SceneObject object)
    : scene_(scene),
      contact_node_(object.contact_node),
      contact_normal_(object.contact_normal),
      fixed_nodes_(object.fixed_nodes),
      origin_m_(object.origin_m),
      model_(object.grid, std::move(object.field),
             Constraints(object.grid, object.fixed_nodes, object.contact_node)) {}

namespace {

// `each(dx, dy, dz)` for every occupied element around a node, (dx, dy, dz) ∈ {−1, 0}³ the
// element's lowest corner relative to the node.
template <typename Each>
void ForEachOccupiedAround(const HexGrid& grid, const MaterialField& field, int node, Each&& each) {
  const auto [ix, iy, iz] = grid.NodeIndices(node);
  for (int dz = -1; dz <= 0; ++dz) {
    for (int dy = -1; dy <= 0; ++dy) {
      for (int dx = -1; dx <= 0; ++dx) {
        const int ex = ix + dx, ey = iy + dy, ez = iz + dz;
        const bool inside = ex >= 0 && ey >= 0 && ez >= 0 && ex + 1 < grid.nx() &&
                            ey + 1 < grid.ny() && ez + 1 < grid.nz();
        if (inside && field.occupied(field.Element(ex, ey, ez))) each(dx, dy, dz);
      }
    }
  }
}

}  // namespace

bool IsObjectSurfaceNode(const HexGrid& grid, const MaterialField& field, int node) {
  int occupied = 0;
  ForEachOccupiedAround(grid, field, node, [&](int, int, int) { ++occupied; });
  return occupied > 0 && occupied < 8;
}

std::array<double, 3> ObjectInwardNormal(const HexGrid& grid, const MaterialField& field,
                                         int node) {
  std::array<int, 3> sum{};
  ForEachOccupiedAround(grid, field, node, [&](int dx, int dy, int dz) {
    sum[0] += 2 * dx + 1;  // towards the element's centre
    sum[1] += 2 * dy + 1;
    sum[2] += 2 * dz + 1;
  });
  const double length = std::hypot(sum[0], sum[1], sum[2]);
  if (length == 0) return {0, 0, 0};
  return {sum[0] / length, sum[1] / length, sum[2] / length};
}

}  // namespace hapticsim
