#include "tools/hapticsim/scene_object_front.hpp"

#include <limits>

#include "core/scene/scene_model.hpp"
#include "core/scene/scene_toml.hpp"

namespace hapticsim::cli {

void MeetSceneObject(const std::string& path, device::MotionSettings* motion) {
  const SceneObject object = DescribeSceneObject(LoadSceneFile(path));
  const HexGrid& grid = object.grid;
  const double h = grid.spacing();
  motion->extent_m = {(grid.nx() - 1) * h, (grid.ny() - 1) * h, (grid.nz() - 1) * h};
  device::ObjectFront& front = motion->front;
  front.spacing_m = h;
  front.columns = {grid.nx() - 1, grid.ny() - 1};
  front.z_m.assign(static_cast<std::size_t>(front.columns[0]) * front.columns[1],
                   std::numeric_limits<double>::quiet_NaN());
  for (int y = 0; y < front.columns[1]; ++y) {
    for (int x = 0; x < front.columns[0]; ++x) {
      for (int z = 0; z < grid.nz() - 1; ++z) {
        if (!object.field.occupied(object.field.Element(x, y, z))) continue;
        front.z_m[static_cast<std::size_t>(x + front.columns[0] * y)] = z * h;
        break;
      }
    }
  }
}

}  // namespace hapticsim::cli
