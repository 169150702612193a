#include "core/scene/scene_geometry.hpp"

#include <algorithm>
#include <cctype>
#include <memory>

#include "core/error.hpp"
#include "core/geometry/nifti_reader.hpp"
#include "core/geometry/surface_mesh_reader.hpp"
#include "core/geometry/file_text.hpp"
#include "core/geometry/voxelise.hpp"

namespace hapticsim {
namespace {

LabelVolume ReadGeometry(const GeometrySettings& geometry) {
  const std::string& file = geometry.file;
  if (EndsWithIgnoringCase(file, ".nii") || EndsWithIgnoringCase(file, ".nii.gz")) {
    return ReadNiftiLabels(file, geometry.spacing_m);
  }
  if (EndsWithIgnoringCase(file, ".stl") || EndsWithIgnoringCase(file, ".obj")) {
    HAPTICSIM_THROW_UNLESS(geometry.spacing_m > 0,
                           "a surface mesh needs geometry.spacing_m > 0, the edge of the voxels "
                           "it becomes (m), e.g. 0.005");
    return VoxeliseClosedSurface(ReadSurfaceMesh(file, geometry.mesh_unit_m),
                                 geometry.spacing_m);
  }
  throw Error("the file's extension is not one hapticsim reads: geometry.file must end in .nii, "
              ".nii.gz (a labelled volume), .stl or .obj (a closed surface)");
}

}  // namespace

void LoadSceneGeometry(Scene* scene) {
  if (!scene->geometry.from_file()) {
    scene->loaded_geometry.reset();
    return;
  }
  if (scene->loaded_geometry && scene->loaded_geometry->source == scene->geometry) return;
  try {
    auto loaded = std::make_shared<LoadedGeometry>();
    loaded->source = scene->geometry;
    loaded->voxels = CropToLabels(ReadGeometry(scene->geometry));
    scene->loaded_geometry = std::move(loaded);
  } catch (const Error& error) {
    throw Error("geometry.file = " + scene->geometry.file + ": " + error.what());
  }
}

}  // namespace hapticsim
