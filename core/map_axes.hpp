#pragma once

#include <array>
#include <string_view>

#include "core/scene.hpp"

namespace hapticsim {

/**
 * The parameters an error map is made over, in the paper's order (Section V-B): material,
 * input, adaptivity. Each is a scene key, so a map point is a scene. The order is part of the
 * map file format: append, never reorder.
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
};
inline constexpr int kNumMapAxes = 9;

struct MapAxisInfo {
  std::string_view scene_key;  ///< e.g. "material.poisson_ratio"
  std::string_view name;       ///< the key's last part, used in JSON: "poisson_ratio"
  std::string_view unit;       ///< SI unit, "" when dimensionless
  std::string_view label;      ///< short column heading: "ν"
  bool integer;                ///< values are whole numbers (no interpolation between them)
  bool material;               ///< a material property (worst case over a neighbourhood)
};

const MapAxisInfo& AxisInfo(int axis);
inline const MapAxisInfo& AxisInfo(MapAxis axis) { return AxisInfo(static_cast<int>(axis)); }

/** A point in parameter space, indexed by MapAxis. */
using MapPoint = std::array<double, kNumMapAxes>;

/** The point of a scene (its values of the nine keys). */
MapPoint PointOfScene(const Scene& scene);

/**
 * `base` with the nine keys set to `point`, adaptivity switched on.
 * @throws Error naming the key when a value is outside the key's range.
 */
Scene SceneAtPoint(const Scene& base, const MapPoint& point);

/** The axis whose name (short or scene key) is `name`, or -1. */
int FindAxis(std::string_view name);

}  // namespace hapticsim
