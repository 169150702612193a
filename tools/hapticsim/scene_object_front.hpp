#pragma once

#include <string>

#include "device/device_motion.hpp"

namespace hapticsim::cli {

/**
 * The object of the scene file at `path` as the daemon makes it (ContactObject), for the simulated
 * device's motion: its lattice's extent along x, y, z (m) and where its front is over each column
 * of voxels (`hapticsim device --scene`, `hapticsim soak --scene`).
 * @throws Error for a scene file that cannot be read.
 */
void MeetSceneObject(const std::string& path, device::MotionSettings* motion);

}  // namespace hapticsim::cli
