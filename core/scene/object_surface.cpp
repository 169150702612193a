#include "core/scene/object_surface.hpp"

#include <algorithm>
#include <array>

namespace hapticsim {

std::vector<std::int32_t> ObjectSurfaceQuads(const SceneObject& object) {
  const HexGrid& grid = object.grid;
  const std::array<int, 3> voxels{grid.nx() - 1, grid.ny() - 1, grid.nz() - 1};
  const int n = std::max({grid.nx(), grid.ny(), grid.nz()});
  const auto occupied = [&](std::array<int, 3> v) {
    for (int c = 0; c < 3; ++c) {
      if (v[c] < 0 || v[c] >= voxels[c]) return false;
    }
    return object.field.occupied(object.field.Element(v[0], v[1], v[2]));
  };
  std::vector<std::int32_t> quads;
  for (int z = 0; z < voxels[2]; ++z) {
    for (int y = 0; y < voxels[1]; ++y) {
      for (int x = 0; x < voxels[0]; ++x) {
        const std::array<int, 3> voxel{x, y, z};
        if (!occupied(voxel)) continue;
        for (int a = 0; a < 3; ++a) {
          for (int side : {0, 1}) {  // the −a face, then the +a face
            std::array<int, 3> beyond = voxel;
            beyond[a] += side == 0 ? -1 : 1;
            if (occupied(beyond)) continue;
            // Corners (0, 0), (1, 0), (1, 1), (0, 1) along b = a + 1 and c = a + 2: b × c = +a,
            // counter-clockwise seen from +a; reversed on the −a face.
            const int b = (a + 1) % 3, c = (a + 2) % 3;
            std::array<std::int32_t, 4> corners{};
            const std::array<std::array<int, 2>, 4> steps{{{0, 0}, {1, 0}, {1, 1}, {0, 1}}};
            for (int k = 0; k < 4; ++k) {
              std::array<int, 3> node = voxel;
              node[a] += side;
              node[b] += steps[static_cast<std::size_t>(k)][0];
              node[c] += steps[static_cast<std::size_t>(k)][1];
              corners[static_cast<std::size_t>(k)] = (node[0] * n + node[1]) * n + node[2];
            }
            if (side == 0) std::swap(corners[1], corners[3]);
            quads.insert(quads.end(), corners.begin(), corners.end());
          }
        }
      }
    }
  }
  return quads;
}

}  // namespace hapticsim
