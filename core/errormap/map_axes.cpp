#include "core/errormap/map_axes.hpp"

#include <cmath>

#include "core/error.hpp"
#include "core/scene/material_contrast.hpp"
#include "core/scene/scene_model.hpp"

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
    // Whole lattice indices in a sweep; a lookup interpolates between mapped nodes.
    {"input.contact_node.x", "contact_node_x", "node", "contact x", true, false, 0},
    {"input.contact_node.y", "contact_node_y", "node", "contact y", true, false, 1},
    {"input.contact_node.z", "contact_node_z", "node", "contact z", true, false, 2},
    // Not a scene key of its own: the [[material]] tables' stiffness relative to the base's.
    {"[[material]] contrast", "material_contrast", "", "E ratio", false, true},
}};

constexpr int kContrast = static_cast<int>(MapAxis::kMaterialContrast);

// The base material's field each of the first four axes is (MapAxis order).
constexpr std::array<double Material::*, 4> kMaterialFields = {
    &Material::poisson_ratio, &Material::density_kg_m3, &Material::damping_per_s,
    &Material::youngs_modulus_pa};
static_assert(static_cast<int>(MapAxis::kYoungsModulus) == 3, "the material axes come first");

}  // namespace

const MapAxisInfo& AxisInfo(int axis) { return kAxes.at(static_cast<size_t>(axis)); }

MapPoint PointOfScene(const Scene& scene) {
  MapPoint point{};
  const LatticeIndex node = SceneContactNode(scene);
  const Material base = BaseMaterial(scene);
  for (int a = 0; a < kNumMapAxes; ++a) {
    const MapAxisInfo& info = AxisInfo(a);
    if (a == kContrast) {
      point[a] = MaterialContrast(scene);
    } else if (info.material) {
      point[a] = base.*kMaterialFields[a];
    } else {
      point[a] = info.node_component >= 0 ? node[info.node_component]
                                          : std::stod(GetSceneValue(scene, info.scene_key));
    }
  }
  return point;
}

Scene SceneAtPoint(const Scene& base, const MapPoint& point) {
  Material material;
  for (int a = 0; a < static_cast<int>(kMaterialFields.size()); ++a) {
    material.*kMaterialFields[a] = point[a];
  }
  Scene scene = SceneWithMaterials(base, material, point[kContrast]);
  // "ix,iy,iz" (the node axes come in component order), set through the scene key so that it is
  // checked as any other value.
  std::string node;
  for (int a = 0; a < kNumMapAxes; ++a) {
    const MapAxisInfo& info = AxisInfo(a);
    if (info.integer) {
      HAPTICSIM_THROW_UNLESS(
          point[a] == std::round(point[a]) && std::abs(point[a]) < 1e9,
          std::string(info.scene_key) + " = " + FormatReal(point[a]) + " is not a whole number");
      if (info.node_component >= 0) {
        if (!node.empty()) node += ',';
        node += std::to_string(static_cast<long>(point[a]));
        continue;
      }
      SetSceneValue(&scene, info.scene_key, std::to_string(static_cast<long>(point[a])));
    } else if (!info.material) {
      SetSceneValue(&scene, info.scene_key, FormatReal(point[a]));
    }
  }
  SetSceneValue(&scene, "input.contact_node", node);
  return scene;
}

int FindAxis(std::string_view name) {
  for (int a = 0; a < kNumMapAxes; ++a) {
    if (kAxes[a].name == name || kAxes[a].scene_key == name) return a;
  }
  return -1;
}

}  // namespace hapticsim
