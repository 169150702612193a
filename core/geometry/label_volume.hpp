#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace hapticsim {

/**
 * An object as labelled voxels on an isotropic lattice: the common form of every geometry source
 * (a segmentation's NIfTI volume, a closed surface mesh voxelised, the paper's cube). Label 0 is
 * outside the object; every other label is a tissue, which a scene's [[material]] table names.
 *
 * Voxel (x, y, z) is the cube [origin + spacing·(x, y, z), origin + spacing·(x+1, y+1, z+1)] in
 * the object frame, metres; voxels are stored x fastest, like HexGrid's elements, so voxel i of a
 * volume is element i of the lattice whose nodes are the voxels' corners.
 */
struct LabelVolume {
  std::array<int, 3> voxels{};          ///< voxel counts along x, y, z
  double spacing_m = 0;                 ///< voxel edge, m
  std::array<double, 3> origin_m{};     ///< lowest corner of voxel (0, 0, 0), m
  std::vector<std::uint16_t> labels;    ///< one per voxel, x fastest; 0 = outside

  std::size_t Index(int x, int y, int z) const {
    return static_cast<std::size_t>(x) +
           static_cast<std::size_t>(voxels[0]) *
               (static_cast<std::size_t>(y) + static_cast<std::size_t>(voxels[1]) *
                                                  static_cast<std::size_t>(z));
  }
  std::uint16_t at(int x, int y, int z) const { return labels[Index(x, y, z)]; }
  std::size_t num_voxels() const {
    return static_cast<std::size_t>(voxels[0]) * static_cast<std::size_t>(voxels[1]) *
           static_cast<std::size_t>(voxels[2]);
  }
};

/// The most voxels a volume read from a file may have before it is resampled (2^28: 512 MiB).
constexpr std::size_t kMaxSourceVoxels = std::size_t{1} << 28;
/// The most labelled voxels (elements) an object may have: beyond it, a coarser spacing is needed.
constexpr std::size_t kMaxObjectVoxels = std::size_t{2} << 20;

/**
 * @throws Error saying what is wrong: a count below 1, more than kMaxSourceVoxels voxels, a
 *         spacing or origin that is not finite (spacing > 0), labels of the wrong length.
 */
void ValidateLabelVolume(const LabelVolume& volume);

/** The distinct non-zero labels, ascending. */
std::vector<std::uint16_t> LabelsPresent(const LabelVolume& volume);

/**
 * The smallest box of voxels holding every labelled one, its origin moved with it.
 * @throws Error when no voxel is labelled, or when more than kMaxObjectVoxels are (naming the
 *         count and asking for a coarser geometry.spacing_m).
 */
LabelVolume CropToLabels(const LabelVolume& volume);

}  // namespace hapticsim
