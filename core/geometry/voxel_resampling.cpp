#include "core/geometry/voxel_resampling.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <sstream>
#include <string>

#include "core/error.hpp"
#include "core/geometry/file_text.hpp"

namespace hapticsim {
namespace {

/// Rounding to the nearest source voxel sends an output centre exactly between two source
/// centres (a coarser spacing of 2 voxel edges does that) to the higher index, whatever the
/// floating-point noise of the inverse affine, which stays far below this (in voxel units).
constexpr double kTieToHigherIndex = 1e-6;
/// The three voxel edges count as equal (spacing_m = 0 may use them) within this ratio.
constexpr double kIsotropyTolerance = 1e-6;
/// A box edge within this fraction of a whole number of output voxels is not rounded up.
constexpr double kWholeVoxelTolerance = 1e-6;

double ColumnNorm(const VoxelAffine& affine, int column) {
  return std::hypot(affine.linear[0][column], affine.linear[1][column], affine.linear[2][column]);
}

}  // namespace

/// The inverse of the affine's linear part, refusing one that flattens the volume.
std::array<std::array<double, 3>, 3> InvertLinear(const VoxelAffine& affine) {
  const auto& a = affine.linear;
  std::array<std::array<double, 3>, 3> inverse{};
  for (int row = 0; row < 3; ++row) {
    for (int column = 0; column < 3; ++column) {
      // Cofactor of a[column][row] (the adjugate is the transposed cofactor matrix).
      const int r1 = (column + 1) % 3, r2 = (column + 2) % 3;
      const int c1 = (row + 1) % 3, c2 = (row + 2) % 3;
      inverse[row][column] = a[r1][c1] * a[r2][c2] - a[r1][c2] * a[r2][c1];
    }
  }
  const double determinant =
      a[0][0] * inverse[0][0] + a[0][1] * inverse[1][0] + a[0][2] * inverse[2][0];
  const double scale = ColumnNorm(affine, 0) * ColumnNorm(affine, 1) * ColumnNorm(affine, 2);
  if (!(std::abs(determinant) > 1e-9 * scale) || !std::isfinite(1.0 / determinant)) {
    throw Error(std::string("the ") + affine.source +
                   " is singular (its voxel axes are not independent): fix the header's "
                   "orientation");
  }
  for (auto& row : inverse) {
    for (double& value : row) value /= determinant;
  }
  return inverse;
}

/// The output voxel edge: `spacing_m`, or the volume's own edge when it is 0.
double ChooseSpacing(const VoxelAffine& affine, double spacing_m) {
  if (!std::isfinite(spacing_m) || spacing_m < 0) {
    throw Error("geometry.spacing_m " + FormatFileNumber(spacing_m) +
                   " must be finite and > 0 (or 0 for the volume's own voxel size)");
  }
  if (spacing_m > 0) return spacing_m;
  const std::array<double, 3> edges = {ColumnNorm(affine, 0), ColumnNorm(affine, 1),
                                       ColumnNorm(affine, 2)};
  const auto [shortest, longest] = std::minmax_element(edges.begin(), edges.end());
  if (*longest - *shortest > kIsotropyTolerance * *longest) {
    throw Error("the voxels are " + FormatFileNumber(edges[0] * 1e3) + " x " +
                   FormatFileNumber(edges[1] * 1e3) + " x " + FormatFileNumber(edges[2] * 1e3) +
                   " mm, not cubes: set geometry.spacing_m to the edge (m) to resample them to");
  }
  return edges[0];  // not an average: an exact edge keeps a same-spacing read exact
}

/// The isotropic output lattice: it covers the world bounding box of the voxel block (index
/// -0.5 .. n-0.5 along each axis), from the box's lowest corner up.
LabelVolume PlanLattice(const VoxelAffine& affine, const std::array<int, 3>& voxels,
                        double spacing_m) {
  std::array<double, 3> low, high;
  low.fill(std::numeric_limits<double>::infinity());
  high.fill(-std::numeric_limits<double>::infinity());
  for (int corner = 0; corner < 8; ++corner) {
    std::array<double, 3> index;
    for (int axis = 0; axis < 3; ++axis) {
      index[axis] = (corner >> axis & 1) ? voxels[axis] - 0.5 : -0.5;
    }
    for (int row = 0; row < 3; ++row) {
      double world = affine.translation[row];
      for (int axis = 0; axis < 3; ++axis) world += affine.linear[row][axis] * index[axis];
      low[row] = std::min(low[row], world);
      high[row] = std::max(high[row], world);
    }
  }
  LabelVolume lattice;
  lattice.spacing_m = spacing_m;
  double total = 1;
  for (int axis = 0; axis < 3; ++axis) {
    const double edges = (high[axis] - low[axis]) / spacing_m;
    const double count = std::max(1.0, std::ceil(edges - kWholeVoxelTolerance));
    total *= count;  // a double: it may be far beyond any integer type before the check
    if (!(total <= static_cast<double>(kMaxSourceVoxels))) {
      throw Error("at a spacing of " + FormatFileNumber(spacing_m) + " m the volume (" +
                     FormatFileNumber((high[0] - low[0]) * 1e3) + " x " +
                     FormatFileNumber((high[1] - low[1]) * 1e3) + " x " +
                     FormatFileNumber((high[2] - low[2]) * 1e3) + " mm) needs more than " +
                     std::to_string(kMaxSourceVoxels) +
                     " voxels: choose a coarser geometry.spacing_m");
    }
    lattice.voxels[axis] = static_cast<int>(count);
    lattice.origin_m[axis] = low[axis];
  }
  return lattice;
}

/// Gives each output voxel the label of the source voxel nearest its centre (0 outside).
void ResampleNearest(const std::vector<std::uint16_t>& source,
                     const std::array<int, 3>& source_voxels, const VoxelAffine& affine,
                     LabelVolume* lattice) {
  const auto inverse = InvertLinear(affine);
  const double s = lattice->spacing_m;
  lattice->labels.assign(lattice->num_voxels(), 0);
  std::size_t out = 0;
  for (int z = 0; z < lattice->voxels[2]; ++z) {
    for (int y = 0; y < lattice->voxels[1]; ++y) {
      // The index of the row's first centre, then one step per voxel along world x.
      const std::array<double, 3> start_world = {
          lattice->origin_m[0] - affine.translation[0],
          lattice->origin_m[1] + s * (y + 0.5) - affine.translation[1],
          lattice->origin_m[2] + s * (z + 0.5) - affine.translation[2]};
      std::array<double, 3> start{}, step{};
      for (int axis = 0; axis < 3; ++axis) {
        for (int k = 0; k < 3; ++k) start[axis] += inverse[axis][k] * start_world[k];
        step[axis] = inverse[axis][0] * s;
      }
      for (int x = 0; x < lattice->voxels[0]; ++x, ++out) {
        std::array<int, 3> nearest;
        bool inside = true;
        for (int axis = 0; axis < 3 && inside; ++axis) {
          const double index =
              std::floor(start[axis] + step[axis] * (x + 0.5) + 0.5 + kTieToHigherIndex);
          inside = index >= 0 && index < source_voxels[axis];
          nearest[axis] = inside ? static_cast<int>(index) : 0;
        }
        if (!inside) continue;
        lattice->labels[out] =
            source[static_cast<std::size_t>(nearest[0]) +
                   static_cast<std::size_t>(source_voxels[0]) *
                       (static_cast<std::size_t>(nearest[1]) +
                        static_cast<std::size_t>(source_voxels[1]) * nearest[2])];
      }
    }
  }
}


}  // namespace hapticsim
