#include "core/map_axes.hpp"

#include <cmath>

#include "core/error.hpp"

namespace hapticsim {
namespace {

constexpr std::array<MapAxisInfo, kNumMapAxes> kAxes{{
    {"material.poisson_ratio", "poisson_ratio", "", "ν", false, true},
    {"material.density", "density", "kg/m^3", "ρ", false, true},
    {"material.damping", "damping", "1/s", "d", false, true},
    {"material.youngs_modulus", "youngs_modulus", "Pa", "E", false, true},
    {"input.amplitude", "amplitude", "m", "amplitude", false, false},
    {"input.frequency", "frequency", "Hz", "frequency", false, false},
    {"adaptivity.secondary_lod", "secondary_lod", "", "lod", true, false},
    {"adaptivity.primary_size", "primary_size", "", "primary size", true, false},
    {"adaptivity.secondary_rate", "secondary_rate", "Hz", "secondary rate", false, false},
}};

}  // namespace

const MapAxisInfo& AxisInfo(int axis) { return kAxes.at(static_cast<size_t>(axis)); }

MapPoint PointOfScene(const Scene& scene) {
  MapPoint point{};
  for (int a = 0; a < kNumMapAxes; ++a) {
    point[a] = std::stod(GetSceneValue(scene, AxisInfo(a).scene_key));
  }
  return point;
}

Scene SceneAtPoint(const Scene& base, const MapPoint& point) {
  Scene scene = base;
  for (int a = 0; a < kNumMapAxes; ++a) {
    const MapAxisInfo& info = AxisInfo(a);
    if (info.integer) {
      HAPTICSIM_THROW_UNLESS(
          point[a] == std::round(point[a]) && std::abs(point[a]) < 1e9,
          std::string(info.scene_key) + " = " + FormatReal(point[a]) + " is not a whole number");
      SetSceneValue(&scene, info.scene_key, std::to_string(static_cast<long>(point[a])));
    } else {
      SetSceneValue(&scene, info.scene_key, FormatReal(point[a]));
    }
  }
  return scene;
}

int FindAxis(std::string_view name) {
  for (int a = 0; a < kNumMapAxes; ++a) {
    if (kAxes[a].name == name || kAxes[a].scene_key == name) return a;
  }
  return -1;
}

}  // namespace hapticsim
