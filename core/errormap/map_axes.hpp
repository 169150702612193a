#pragma once

#include <array>
#include <string_view>

#include "core/scene/scene.hpp"

namespace hapticsim {

/**
 * The parameters an error map is made over, in the paper's order (Section V-B): material,
 * input, adaptivity, then the contact node and the material contrast. Each sets the scene (the
 * contact node's three lattice indices are the three parts of input.contact_node; the material
 * axes and the contrast set the base material and the others with it, see material_contrast.hpp),
 * so a map point is a scene. The order is part of the map file format: append, never reorder.
 */
enum class MapAxis : int {
  kPoissonRatio,
  kDensity,
  kDamping,
  kYoungsModulus,
  kAmplitude,
  kFrequency,
  kSecondaryLod,
  kPrimarySize,
  kSecondaryRate,
  kContactNodeX,  ///< lattice indices of the driven node (input.contact_node)
  kContactNodeY,
  kContactNodeZ,
  kMaterialContrast,  ///< E of the stiffest other material / E of the base; 1 for one material
};
inline constexpr int kNumMapAxes = 13;

struct MapAxisInfo {
  std::string_view scene_key;  ///< e.g. "material.poisson_ratio"; what the axis sets, in messages
  std::string_view name;       ///< the key's last part, used in JSON: "poisson_ratio"
  std::string_view unit;       ///< SI unit, "" when dimensionless
  std::string_view label;      ///< short column heading: "ν"
  /// Values are whole numbers in a sweep. A lookup interpolates between grid values on every
  /// axis; queries of spacing factor and primary size hit them exactly, contact nodes may not.
  bool integer;
  bool material;  ///< a material property (worst case over a neighbourhood)
  /// For the contact-node axes, the index (0, 1, 2: x, y, z) of input.contact_node they set;
  /// -1 for the others, which are scene keys of their own.
  int node_component = -1;
};

const MapAxisInfo& AxisInfo(int axis);
inline const MapAxisInfo& AxisInfo(MapAxis axis) { return AxisInfo(static_cast<int>(axis)); }

/** A point in parameter space, indexed by MapAxis. */
using MapPoint = std::array<double, kNumMapAxes>;

/**
 * The point of a scene: its values of the map's keys, the contact node of the scene's own, its
 * base material and its contrast (MaterialContrast).
 */
MapPoint PointOfScene(const Scene& scene);

/**
 * `base` with the map's keys set to `point` (the contact node to the point's three indices, the
 * materials by SceneWithMaterials), adaptivity switched on. Whether the node is on the surface is
 * ValidateScene's check.
 * @throws Error naming the key when a value is outside the key's range, or a contrast ≠ 1 on an
 * object of one material.
 */
Scene SceneAtPoint(const Scene& base, const MapPoint& point);

/** The axis whose name (short or scene key) is `name`, or -1. */
int FindAxis(std::string_view name);

}  // namespace hapticsim
