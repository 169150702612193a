#pragma once

#include "core/scene/scene.hpp"

namespace hapticsim::testing {

/** The default scene with adaptivity on: primary size r, spacing factor k, secondary rate, ν. */
inline Scene AdaptiveScene(int primary_size, int lod, double rate_hz, double nu = 0.45) {
  Scene scene;
  scene.material.poisson_ratio = nu;
  scene.adaptivity.primary_size = primary_size;
  scene.adaptivity.secondary_lod = lod;
  scene.adaptivity.secondary_rate_hz = rate_hz;
  return scene;
}

}  // namespace hapticsim::testing
