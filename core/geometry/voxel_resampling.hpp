#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "core/geometry/label_volume.hpp"

namespace hapticsim {

/**
 * Where a volume's voxels are: world (m) = linear · (i, j, k) + translation, voxel centres at
 * whole indices (NIfTI's convention), and which of the header's fields it came from.
 */
struct VoxelAffine {
  std::array<std::array<double, 3>, 3> linear{};
  std::array<double, 3> translation{};
  const char* source = "";  ///< "sform", "qform" or "pixdim", for messages
};

/**
 * The inverse of the affine's linear part.
 * @throws Error when it flattens the volume (its voxel axes are not independent).
 */
std::array<std::array<double, 3>, 3> InvertLinear(const VoxelAffine& affine);

/**
 * The output voxel edge: `spacing_m`, or the volume's own edge when it is 0, which the three
 * edges must then share.
 * @throws Error when `spacing_m` is not finite and ≥ 0, or 0 with voxels that are not cubes
 *         (naming their edges, mm, and geometry.spacing_m).
 */
double ChooseSpacing(const VoxelAffine& affine, double spacing_m);

/**
 * The isotropic output lattice (labels not yet filled): it covers the world bounding box of the
 * voxel block (index −0.5 … n − 0.5 along each axis), from the box's lowest corner up.
 * @throws Error when it would exceed kMaxSourceVoxels (asking for a coarser geometry.spacing_m).
 */
LabelVolume PlanLattice(const VoxelAffine& affine, const std::array<int, 3>& voxels,
                        double spacing_m);

/**
 * Gives each voxel of `lattice` the label of the `source` voxel (x fastest, `source_voxels`
 * counts) nearest its centre, 0 outside the source. A centre exactly between two source centres
 * goes to the higher index, whatever the floating-point noise of the inverse affine.
 */
void ResampleNearest(const std::vector<std::uint16_t>& source,
                     const std::array<int, 3>& source_voxels, const VoxelAffine& affine,
                     LabelVolume* lattice);

}  // namespace hapticsim
