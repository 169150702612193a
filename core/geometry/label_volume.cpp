#include "core/geometry/label_volume.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.hpp"

namespace hapticsim {

void ValidateLabelVolume(const LabelVolume& volume) {
  for (int axis = 0; axis < 3; ++axis) {
    HAPTICSIM_THROW_UNLESS(volume.voxels[axis] >= 1,
                           "a label volume needs at least one voxel along each axis, not " +
                               std::to_string(volume.voxels[axis]) + " along " +
                               "xyz"[axis]);
    HAPTICSIM_THROW_UNLESS(std::isfinite(volume.origin_m[axis]),
                           "a label volume's origin must be finite");
  }
  HAPTICSIM_THROW_UNLESS(volume.num_voxels() <= kMaxSourceVoxels,
                         "a label volume of " + std::to_string(volume.num_voxels()) +
                             " voxels is larger than the " + std::to_string(kMaxSourceVoxels) +
                             " hapticsim reads");
  HAPTICSIM_THROW_UNLESS(std::isfinite(volume.spacing_m) && volume.spacing_m > 0,
                         "a label volume's voxel spacing must be finite and > 0 m");
  HAPTICSIM_THROW_UNLESS(volume.labels.size() == volume.num_voxels(),
                         "a label volume of " + std::to_string(volume.num_voxels()) +
                             " voxels has " + std::to_string(volume.labels.size()) + " labels");
}

std::vector<std::uint16_t> LabelsPresent(const LabelVolume& volume) {
  std::vector<bool> seen(65536, false);
  for (std::uint16_t label : volume.labels) seen[label] = true;
  std::vector<std::uint16_t> present;
  for (std::size_t label = 1; label < seen.size(); ++label) {
    if (seen[label]) present.push_back(static_cast<std::uint16_t>(label));
  }
  return present;
}

LabelVolume CropToLabels(const LabelVolume& volume) {
  ValidateLabelVolume(volume);
  std::array<int, 3> low = volume.voxels, high = {-1, -1, -1};
  std::size_t labelled = 0;
  for (int z = 0; z < volume.voxels[2]; ++z) {
    for (int y = 0; y < volume.voxels[1]; ++y) {
      for (int x = 0; x < volume.voxels[0]; ++x) {
        if (volume.at(x, y, z) == 0) continue;
        ++labelled;
        const std::array<int, 3> at = {x, y, z};
        for (int axis = 0; axis < 3; ++axis) {
          low[axis] = std::min(low[axis], at[axis]);
          high[axis] = std::max(high[axis], at[axis]);
        }
      }
    }
  }
  HAPTICSIM_THROW_UNLESS(labelled > 0, "the geometry has no labelled voxel: nothing to simulate");
  HAPTICSIM_THROW_UNLESS(labelled <= kMaxObjectVoxels,
                         "the geometry has " + std::to_string(labelled) +
                             " labelled voxels at this spacing, more than the " +
                             std::to_string(kMaxObjectVoxels) +
                             " elements hapticsim simulates: choose a coarser geometry.spacing_m");
  LabelVolume cropped;
  cropped.spacing_m = volume.spacing_m;
  for (int axis = 0; axis < 3; ++axis) {
    cropped.voxels[axis] = high[axis] - low[axis] + 1;
    cropped.origin_m[axis] = volume.origin_m[axis] + volume.spacing_m * low[axis];
  }
  cropped.labels.resize(cropped.num_voxels());
  for (int z = 0; z < cropped.voxels[2]; ++z) {
    for (int y = 0; y < cropped.voxels[1]; ++y) {
      for (int x = 0; x < cropped.voxels[0]; ++x) {
        cropped.labels[cropped.Index(x, y, z)] = volume.at(x + low[0], y + low[1], z + low[2]);
      }
    }
  }
  return cropped;
}

}  // namespace hapticsim
