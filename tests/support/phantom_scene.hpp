#pragma once

#include "core/scene/scene.hpp"
#include "tests/support/voxel_scene.hpp"

namespace hapticsim::testing {

/**
 * The palpation phantom's make-up (examples/palpation/), built in place: a block of 32 × 16 × 12
 * voxels of 2.5 mm (10 kPa) with a sphere of radius 3 voxels eight times stiffer under the middle
 * of its front face, held on its back face; primary size 3, secondary lod 2, both at 1000 Hz.
 * Stiff enough that every region takes 6 substeps a period.
 */
inline Scene StiffPhantomScene() {
  constexpr double h = 0.0025;
  Scene scene = VoxelScene(32, 16, 12, h, [](int x, int y, int z) {
    const double dx = x + 0.5 - 16, dy = y + 0.5 - 8, dz = z + 0.5 - 4.5;
    return dx * dx + dy * dy + dz * dz <= 9.0 ? 2 : 1;
  });
  HoldPlaneZ(&scene, 12 * h);
  Material tissue, inclusion;
  inclusion.youngs_modulus_pa = 8 * tissue.youngs_modulus_pa;
  scene.materials = {{1, tissue}, {2, inclusion}};
  scene.adaptivity.primary_size = 3;
  scene.adaptivity.secondary_lod = 2;
  scene.adaptivity.secondary_rate_hz = 1000;
  scene.adaptivity.outer_rate_hz = 1000;
  return scene;
}

}  // namespace hapticsim::testing
