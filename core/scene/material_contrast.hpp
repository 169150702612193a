#pragma once

#include "core/fem/material.hpp"
#include "core/scene/scene.hpp"

namespace hapticsim {

/**
 * An object of several materials seen as a base tissue and its contrasts, the error map's view
 * of it (the paper, Section VII: heterogeneous material as the next axis of the error model).
 *
 * The base is the [[material]] table of the lowest label (the surrounding tissue, by the
 * convention segmentation tools follow: label 1 is the organ, higher labels what is in it), or
 * material.* when there are no tables. The contrast is the stiffness ratio of the stiffest other
 * material to the base: E_other / E_base, 1 for an object of one material.
 */
Material BaseMaterial(const Scene& scene);
double MaterialContrast(const Scene& scene);

/**
 * `scene` with its base material set to `base` and its other materials moved with it: each keeps
 * its own ν and its ratios of density and damping to the base's (its damping as it was when the
 * base's is 0), and its Young's modulus scales so that the stiffest of them is `contrast` × E of
 * `base`. So a map point is a scene, and scaling E and ρ of the base together scales every
 * material's E and ρ together (the sweep's similarity in E/ρ stays exact).
 * @throws Error naming the key and table of a value outside its range, or a contrast ≠ 1 on an
 * object of one material.
 */
Scene SceneWithMaterials(const Scene& scene, const Material& base, double contrast);

}  // namespace hapticsim
