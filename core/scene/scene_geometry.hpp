#pragma once

#include "core/scene/scene.hpp"

namespace hapticsim {

/**
 * Reads and voxelises the scene's geometry.file into Scene::loaded_geometry, cropped to its
 * labelled voxels, unless what is loaded was made from the same geometry settings already; clears
 * it when the scene is the built-in cube. A .nii or .nii.gz file is a labelled volume (resampled
 * to geometry.spacing_m, or its own voxel edge when that is 0); a .stl or .obj file is a closed
 * surface in units of geometry.mesh_unit, voxelised at geometry.spacing_m as label 1.
 * @throws Error naming geometry.file and what is wrong with it.
 */
void LoadSceneGeometry(Scene* scene);

}  // namespace hapticsim
