#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <memory>

#include "core/geometry/label_volume.hpp"
#include "core/scene/scene.hpp"

namespace hapticsim::testing {

/**
 * A scene whose object is the voxels `label(x, y, z)` (0: empty) of nx × ny × nz voxels of edge
 * `spacing_m`, as if read from a geometry file: no file is written.
 */
inline Scene VoxelScene(int nx, int ny, int nz, double spacing_m,
                        const std::function<int(int, int, int)>& label) {
  Scene scene;
  scene.geometry.file = "voxels-made-by-the-test.nii";
  scene.geometry.spacing_m = spacing_m;
  auto loaded = std::make_shared<LoadedGeometry>();
  loaded->source = scene.geometry;
  LabelVolume& v = loaded->voxels;
  v.voxels = {nx, ny, nz};
  v.spacing_m = spacing_m;
  v.labels.resize(v.num_voxels());
  for (int z = 0; z < nz; ++z) {
    for (int y = 0; y < ny; ++y) {
      for (int x = 0; x < nx; ++x)
        v.labels[v.Index(x, y, z)] = static_cast<std::uint16_t>(label(x, y, z));
    }
  }
  scene.loaded_geometry = loaded;
  return scene;
}

/** `scene` with its nodes on the plane z = `z_m` (its back face) held: one [[support]] plane. */
inline void HoldPlaneZ(Scene* scene, double z_m) {
  SupportRegion back;
  back.kind = SupportRegion::Kind::kPlane;
  back.point_m = {0, 0, z_m};
  back.normal = {0, 0, 1};
  scene->supports = {back};
}

/** A [[support]] box: every node inside [low, high] (m) held. */
inline SupportRegion SupportBox(std::array<double, 3> low, std::array<double, 3> high) {
  SupportRegion box;
  box.kind = SupportRegion::Kind::kBox;
  box.box_min_m = low;
  box.box_max_m = high;
  return box;
}

/** n³ voxels. */
inline Scene VoxelScene(int n, double spacing_m, const std::function<int(int, int, int)>& label) {
  return VoxelScene(n, n, n, spacing_m, label);
}

}  // namespace hapticsim::testing
