#pragma once

#include <array>
#include <string>
#include <vector>

#include "core/fem/elastic_model.hpp"
#include "core/scene/scene.hpp"

namespace hapticsim {

/**
 * What a scene's object is, before it becomes a model: its lattice and materials, the nodes its
 * supports hold (ascending), the contact node and its unit inward normal, and where node 0 sits in
 * the geometry's own frame (m). What SceneModel steps and RegionPartition splits.
 */
struct SceneObject {
  HexGrid grid;
  MaterialField field;
  std::vector<int> fixed_nodes;
  int contact_node = 0;
  std::array<double, 3> contact_normal{};
  std::array<double, 3> origin_m{};
};

/**
 * The object of a scene (see SceneModel for which): validated, its supports checked to hold it.
 * @throws Error as SceneModel's constructor.
 */
SceneObject DescribeSceneObject(const Scene& scene);

/**
 * The contact node of any scene, as lattice indices: input.contact_node, or the default (the
 * cube's middle front node; on a geometry, the one SceneModel chooses).
 * @throws Error as DescribeSceneObject, on a geometry.
 */
LatticeIndex SceneContactNode(const Scene& scene);

/**
 * Why `node` cannot be `scene`'s contact node, or "" when it can: on the cube,
 * ContactNodeProblem's rule; on a geometry, what DescribeSceneObject says of it (outside the
 * lattice, not on the object's surface, held by a support, no inward direction).
 */
std::string ContactNodeProblemOn(const Scene& scene, const LatticeIndex& node);

/**
 * A scene as a model ready to step: the object's lattice and materials, its supports fixed in
 * all three components, and the contact node driven in all three (driven DOF order x, y, z).
 *
 * The object is the paper's cube of mesh.nodes³ nodes and edge mesh.edge, or the voxels of
 * geometry.file (Scene::loaded_geometry), one hexahedron per voxel, each of its label's material.
 * The supports are the [[support]] tables' nodes, or the cube's four back corners. The contact is
 * input.contact_node, or by default the paper's: the cube's middle front node; on a geometry,
 * the front-most node (least z) of the lattice column nearest the object's centre in x and y.
 */
class SceneModel {
 public:
  /**
   * @throws Error when the scene is invalid (ValidateScene), its geometry file is set but not
   *         read, the contact node is not a free node on the object's surface, or the supports
   *         leave a rigid-body mode (saying which part and what to add).
   */
  explicit SceneModel(const Scene& scene);

  const Scene& scene() const { return scene_; }
  const ElasticModel& model() const { return model_; }
  int contact_node() const { return contact_node_; }
  /** The unit inward normal the device drives the contact node along. */
  const std::array<double, 3>& contact_normal() const { return contact_normal_; }
  /** The held nodes, ascending. */
  const std::vector<int>& fixed_nodes() const { return fixed_nodes_; }
  /** Where node 0 of the lattice is in the geometry's own frame (a file's coordinates), m. */
  const std::array<double, 3>& origin_m() const { return origin_m_; }

 private:
  SceneModel(const Scene& scene, SceneObject object);

  Scene scene_;
  int contact_node_ = 0;
  std::array<double, 3> contact_normal_{};
  std::vector<int> fixed_nodes_;
  std::array<double, 3> origin_m_{};
  ElasticModel model_;
};

/** Per node of `field` on `grid`: on the surface, i.e. touching an empty or outside element. */
bool IsObjectSurfaceNode(const HexGrid& grid, const MaterialField& field, int node);

/**
 * The unit inward normal of a surface node of an object on a lattice: the mean direction from the
 * node to the centres of the occupied elements around it. {0, 0, 0} when they balance out (an
 * inside node, or a saddle), where no direction is the surface's.
 */
std::array<double, 3> ObjectInwardNormal(const HexGrid& grid, const MaterialField& field, int node);

}  // namespace hapticsim
