#pragma once

#include <array>

#include "core/fem/elastic_model.hpp"
#include "core/scene/scene.hpp"

namespace hapticsim {

/**
 * The paper's experiment as a model: a cube of mesh.nodes³ nodes and edge mesh.edge, the four
 * corner nodes of the back face (z = edge) fixed in all three components, and the middle node of
 * the front face (z = 0) driven in all three components. With an even node count the "middle"
 * node is the one just below the centre in x and y.
 *
 * Driven DOF order: x, y, z of the contact node.
 */
class CubeScene {
 public:
  /** @throws Error when the scene is invalid (see ValidateScene). */
  explicit CubeScene(const Scene& scene);

  const Scene& scene() const { return scene_; }
  const ElasticModel& model() const { return model_; }
  int contact_node() const { return contact_node_; }
  /** The four fixed back-face corners. */
  const std::array<int, 4>& fixed_nodes() const { return fixed_nodes_; }

 private:
  Scene scene_;
  int contact_node_;
  std::array<int, 4> fixed_nodes_;
  ElasticModel model_;
};

}  // namespace hapticsim
