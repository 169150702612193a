#include "core/scene/material_contrast.hpp"

#include <algorithm>
#include <cmath>

#include "core/error.hpp"
#include "core/scene/label_materials.hpp"

namespace hapticsim {
namespace {

// The base table's index in scene.materials (the lowest label), or -1 without tables.
int BaseTable(const Scene& scene) {
  int base = -1;
  for (int t = 0; t < static_cast<int>(scene.materials.size()); ++t) {
    if (base < 0 || scene.materials[t].label < scene.materials[base].label) base = t;
  }
  return base;
}

// E of the stiffest material other than the base, over E of the base; 1 when there is none.
double ContrastOf(const Scene& scene, int base) {
  if (base < 0 || scene.materials.size() < 2) return 1;
  double stiffest = 0;
  for (int t = 0; t < static_cast<int>(scene.materials.size()); ++t) {
    if (t != base) stiffest = std::max(stiffest, scene.materials[t].material.youngs_modulus_pa);
  }
  return stiffest / scene.materials[base].material.youngs_modulus_pa;
}

// Sets one table value through the [[material]] key, so a value out of range is refused with
// the table's label and the key's allowed range.
void SetTableValue(LabelMaterial* table, const char* key, double value) {
  try {
    SetMaterialTableValue(table, key, FormatReal(value));
  } catch (const Error& e) {
    throw Error("[[material]] label " + std::to_string(table->label) + ": " + e.what());
  }
}

}  // namespace

Material BaseMaterial(const Scene& scene) {
  const int base = BaseTable(scene);
  return base < 0 ? scene.material : scene.materials[base].material;
}

double MaterialContrast(const Scene& scene) { return ContrastOf(scene, BaseTable(scene)); }

Scene SceneWithMaterials(const Scene& scene, const Material& base, double contrast) {
  Scene out = scene;
  SetSceneValue(&out, "material.youngs_modulus", FormatReal(base.youngs_modulus_pa));
  SetSceneValue(&out, "material.poisson_ratio", FormatReal(base.poisson_ratio));
  SetSceneValue(&out, "material.density", FormatReal(base.density_kg_m3));
  SetSceneValue(&out, "material.damping", FormatReal(base.damping_per_s));
  const int b = BaseTable(scene);
  const bool several = b >= 0 && scene.materials.size() >= 2;
  HAPTICSIM_THROW_UNLESS(
      std::isfinite(contrast) && contrast > 0 && (several || contrast == 1),
      "material contrast = " + FormatReal(contrast) +
          (several ? " must be finite and > 0"
                   : " needs an object of several materials ([[material]] tables); this one has "
                     "one, whose contrast is 1"));
  if (b < 0) return out;
  // Ratios to the base, so that a table equal to the base (or the stiffest one at contrast 1)
  // comes out exactly equal to it: labels of equal material are one material to the regions
  // (IndexLabelMaterials), so one ulp off would change the mesh.
  const Material& was = scene.materials[b].material;
  const double scene_contrast = ContrastOf(scene, b);
  for (int t = 0; t < static_cast<int>(out.materials.size()); ++t) {
    LabelMaterial& table = out.materials[t];
    if (t == b) {
      table.material = out.material;
      continue;
    }
    const Material own = table.material;
    const double stiffness = own.youngs_modulus_pa / was.youngs_modulus_pa;
    SetTableValue(
        &table, "youngs_modulus",
        base.youngs_modulus_pa *
            (stiffness == scene_contrast ? contrast : stiffness * (contrast / scene_contrast)));
    SetTableValue(&table, "density", base.density_kg_m3 * (own.density_kg_m3 / was.density_kg_m3));
    if (was.damping_per_s > 0) {
      SetTableValue(&table, "damping",
                    base.damping_per_s * (own.damping_per_s / was.damping_per_s));
    }
  }
  return out;
}

}  // namespace hapticsim
