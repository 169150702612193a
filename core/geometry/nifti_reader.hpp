#pragma once

#include <string>

#include "core/geometry/label_volume.hpp"

namespace hapticsim {

/**
 * Reads a labelled NIfTI-1 or NIfTI-2 volume (.nii or .nii.gz, as segmentation tools export it)
 * and resamples it, nearest label, onto an isotropic lattice of `spacing_m` aligned with the
 * world axes of its header (sform, else qform, else pixdim), in metres (the header's xyzt_units;
 * millimetres when it names none). `spacing_m` = 0 takes the volume's own voxel edge, which then
 * must be the same along the three axes.
 *
 * The lattice starts at the lowest corner of the world bounding box of the voxel block (voxel
 * centres at integer indices, so the block spans index -0.5 .. n-0.5) and covers it; each output
 * voxel takes the label of the source voxel nearest its centre (a tie goes to the higher source
 * index), 0 outside the block. A volume whose axes are the world's, permuted or flipped, read at
 * its own spacing comes out label for label. Not cropped: see CropToLabels. A .nii.gz is
 * decompressed twice, to make sure it holds its data before memory is allocated for it.
 * @throws Error naming the file and what is wrong: unreadable or truncated, not 3-D, a data type
 *         that is not integer labels, negative or non-integral labels, a spacing that is not
 *         finite and positive, anisotropic voxels without `spacing_m`, too many voxels.
 */
LabelVolume ReadNiftiLabels(const std::string& path, double spacing_m);

}  // namespace hapticsim
