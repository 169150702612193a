#pragma once

#include <cstdint>
#include <vector>

#include "core/scene/scene_model.hpp"

namespace hapticsim {

/**
 * The surface of a scene's object, to draw it deformed: every face between an occupied voxel and
 * an empty one (or the lattice's end), as four lattice-node ids wound outwards (counter-clockwise
 * seen from outside), in deformation_t's numbering — id = (ix · n + iy) · n + iz with n the
 * lattice's largest node count (its nodes_per_axis). Every corner is a node deformation_t
 * carries. On a box these are the squares of its six faces, which a reader can find from the
 * surface ids alone; an object that leaves voxels empty needs them, since its surface nodes do
 * not say which of the squares between them are faces. (hapticsim view --scene draws these.)
 */
std::vector<std::int32_t> ObjectSurfaceQuads(const SceneObject& object);

}  // namespace hapticsim
