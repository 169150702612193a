#include "core/geometry/voxelise.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <numeric>
#include <sstream>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "core/error.hpp"

// How the inside test stays right when a ray grazes an edge or a vertex.
//
// Each (x, y) column of voxel centres casts one ray along +z; a centre is inside when an odd
// number of the surface's crossings with that ray lie at or below it (parity, so the triangles'
// orientation does not matter). Counting crossings is only right if a ray through a shared edge
// or vertex meets the triangles there as a ray just beside it would (one of two across an edge);
// floating-point point-in-triangle tests get this wrong in both directions. So:
//  1. Every vertex is snapped to a fixed-point grid of 2^24 steps per voxel (moving it by at most
//     spacing / 2^25), on which the voxel centres lie exactly. Corners at one position snap alike,
//     so the snapped mesh is still closed.
//  2. On that grid, orientation tests are exact in 128-bit integers (coordinates < 2^53).
//  3. A centre exactly on a projected edge or vertex is treated as if moved by (ε, ε²), ε → 0
//     (symbolic perturbation), which gives the half-open "bottom-left" rule: each point of the
//     plane is in exactly one of the triangles that tile it around a shared edge or vertex.
//     Triangles seen edge-on from the ray (zero projected area) are never crossed, as the moved
//     ray misses them. Along z, a crossing exactly at a centre counts as below it (the centre
//     moved by +ε', ε' ≫ ε). So a box whose faces lie on centre planes is half-open [low, high).
//  4. Where a crossing lies along z is computed in floating point (exact for a level face): its
//     rounding can move a face by a hair, but never lose or double a crossing.
// Three rays per centre with a majority vote would cost three times as much and still need exact
// tests; one ray with exact tests is correct alone.
//
// Cost: triangles are swept row by row (y), each tested only against the columns inside its
// bounding box, so the work is ~ O(triangles · columns touched + voxels), the memory one row.

namespace hapticsim {
namespace {

__extension__ typedef __int128 Wide;  // GCC and Clang; exact for the products below
constexpr std::int64_t kStepsPerVoxel = std::int64_t{1} << 24;
constexpr std::int64_t kHalfVoxel = kStepsPerVoxel / 2;

struct Point2 {
  std::int64_t x, y;  ///< grid steps from the lattice origin
};

struct SnappedTriangle {
  std::array<Point2, 3> corners;  ///< counter-clockwise seen from +z
  std::array<double, 3> z;        ///< grid steps from the lattice origin (whole numbers)
  Wide twice_area;                ///< > 0
  int first_row, last_row;  ///< rows (y) of centres in its bounding box; empty if first > last
  int first_column, last_column;  ///< the same along x
};

Wide Orient(const Point2& a, const Point2& b, const Point2& p) {
  return Wide(b.x - a.x) * Wide(p.y - a.y) - Wide(b.y - a.y) * Wide(p.x - a.x);
}

/// Whether p is on the inner side of the directed edge `from` → `to` of a counter-clockwise
/// triangle, p moved by (ε, ε²) when it is on the edge's line: the bottom-left rule.
bool EdgeCovers(const Point2& from, const Point2& to, const Point2& p) {
  const Wide side = Orient(from, to, p);
  if (side != 0) return side > 0;
  // Orient(from, to, p + (ε, ε²)) = ε² · dx − ε · dy: the sign of −dy, else of dx.
  const std::int64_t dy = to.y - from.y;
  return dy < 0 || (dy == 0 && to.x > from.x);
}

std::int64_t FloorDiv(std::int64_t numerator, std::int64_t denominator) {
  const std::int64_t quotient = numerator / denominator;
  return (numerator % denominator != 0 && numerator < 0) ? quotient - 1 : quotient;
}

/// The indices [first, last] of centres (i + ½) · step that lie in [low, high], within [0, count).
std::pair<int, int> CentresWithin(std::int64_t low, std::int64_t high, int count) {
  const std::int64_t first = -FloorDiv(-(low - kHalfVoxel), kStepsPerVoxel);
  const std::int64_t last = FloorDiv(high - kHalfVoxel, kStepsPerVoxel);
  return {static_cast<int>(std::max<std::int64_t>(first, 0)),
          static_cast<int>(std::min<std::int64_t>(last, count - 1))};
}

struct Lattice {
  std::array<double, 3> origin_m;
  double spacing_m;
  std::array<int, 3> voxels;

  std::int64_t Snap(double coordinate_m, int axis) const {
    return std::llround((coordinate_m - origin_m[axis]) / spacing_m *
                        static_cast<double>(kStepsPerVoxel));
  }
};

std::string FormatMetres(double value) {
  std::ostringstream out;
  out.precision(6);
  out << value << " m";
  return out.str();
}

Lattice ChooseLattice(const TriangleMesh& mesh, double spacing_m) {
  Lattice lattice{};
  lattice.spacing_m = spacing_m;
  std::array<double, 3> high{};
  for (int axis = 0; axis < 3; ++axis) {
    lattice.origin_m[axis] = high[axis] = mesh.vertices[mesh.triangles[0][0]][axis];
  }
  for (const auto& triangle : mesh.triangles) {
    for (int corner : triangle) {
      for (int axis = 0; axis < 3; ++axis) {
        lattice.origin_m[axis] = std::min(lattice.origin_m[axis], mesh.vertices[corner][axis]);
        high[axis] = std::max(high[axis], mesh.vertices[corner][axis]);
      }
    }
  }
  double total = 1;
  std::array<double, 3> counts{};
  for (int axis = 0; axis < 3; ++axis) {
    counts[axis] = std::max(1.0, std::ceil((high[axis] - lattice.origin_m[axis]) / spacing_m));
    total *= counts[axis];
  }
  // Compared as doubles: an extent of 1e300 m must not overflow an int on its way to the check.
  if (!(total <= static_cast<double>(kMaxSourceVoxels))) {
    std::ostringstream message;
    message << "voxelising the surface mesh at a spacing of " << FormatMetres(spacing_m)
            << " needs " << counts[0] << " x " << counts[1] << " x " << counts[2]
            << " voxels, more than the " << kMaxSourceVoxels
            << " hapticsim voxelises: choose a coarser geometry.spacing_m";
    throw Error(message.str());
  }
  for (int axis = 0; axis < 3; ++axis) lattice.voxels[axis] = static_cast<int>(counts[axis]);
  return lattice;
}

/// The triangle on the grid, counter-clockwise from +z; false when it is seen edge-on from +z
/// (no ray crosses it) or its bounding box holds no column of centres.
bool SnapTriangle(const TriangleMesh& mesh, const std::array<int, 3>& triangle,
                  const Lattice& lattice, SnappedTriangle* snapped) {
  for (int k = 0; k < 3; ++k) {
    const auto& vertex = mesh.vertices[triangle[k]];
    snapped->corners[k] = {lattice.Snap(vertex[0], 0), lattice.Snap(vertex[1], 1)};
    snapped->z[k] = static_cast<double>(lattice.Snap(vertex[2], 2));
  }
  snapped->twice_area = Orient(snapped->corners[0], snapped->corners[1], snapped->corners[2]);
  if (snapped->twice_area == 0) return false;
  if (snapped->twice_area < 0) {
    std::swap(snapped->corners[1], snapped->corners[2]);
    std::swap(snapped->z[1], snapped->z[2]);
    snapped->twice_area = -snapped->twice_area;
  }
  const auto& c = snapped->corners;
  std::tie(snapped->first_column, snapped->last_column) = CentresWithin(
      std::min({c[0].x, c[1].x, c[2].x}), std::max({c[0].x, c[1].x, c[2].x}), lattice.voxels[0]);
  std::tie(snapped->first_row, snapped->last_row) = CentresWithin(
      std::min({c[0].y, c[1].y, c[2].y}), std::max({c[0].y, c[1].y, c[2].y}), lattice.voxels[1]);
  return snapped->first_column <= snapped->last_column && snapped->first_row <= snapped->last_row;
}

struct Crossing {
  int column;  ///< x index of the ray
  double z;    ///< grid steps from the lattice origin
  bool operator<(const Crossing& other) const {
    return column != other.column ? column < other.column : z < other.z;
  }
};

/// Appends where the rays of `row` that the triangle covers cross it.
void AddCrossings(const SnappedTriangle& triangle, int row, std::vector<Crossing>* crossings) {
  const auto& [a, b, c] = triangle.corners;
  const std::int64_t y = row * kStepsPerVoxel + kHalfVoxel;
  for (int column = triangle.first_column; column <= triangle.last_column; ++column) {
    const Point2 p{column * kStepsPerVoxel + kHalfVoxel, y};
    if (!EdgeCovers(a, b, p) || !EdgeCovers(b, c, p) || !EdgeCovers(c, a, p)) continue;
    // Barycentric weights of b and c; z is exact where the triangle is level (z_b = z_c = z_a).
    const double weight_b = static_cast<double>(Orient(c, a, p));
    const double weight_c = static_cast<double>(Orient(a, b, p));
    const double z = triangle.z[0] + (weight_b * (triangle.z[1] - triangle.z[0]) +
                                      weight_c * (triangle.z[2] - triangle.z[0])) /
                                         static_cast<double>(triangle.twice_area);
    crossings->push_back({column, z});
  }
}

/// Labels the centres of one column between each pair of its crossings: [in, out), half-open.
void FillBetweenCrossings(const Crossing* crossings, std::size_t count, int row,
                          std::uint16_t label, LabelVolume* volume) {
  const double step = static_cast<double>(kStepsPerVoxel);
  const double top = volume->voxels[2];
  // A closed surface crosses a ray an even number of times (the tests are exact); were one
  // left over, it would be ignored rather than fill the column to the top.
  for (std::size_t k = 0; k + 1 < count; k += 2) {
    // Centre (i + ½) · step ≥ z ⟺ i ≥ z / step − ½, exact since step is a power of two.
    const double first = std::clamp(std::ceil(crossings[k].z / step - 0.5), 0.0, top);
    const double end = std::clamp(std::ceil(crossings[k + 1].z / step - 0.5), 0.0, top);
    for (int i = static_cast<int>(first); i < static_cast<int>(end); ++i) {
      volume->labels[volume->Index(crossings[k].column, row, i)] = label;
    }
  }
}

/// Labels the centres of `row` inside the surface, from its crossings sorted by (column, z).
void FillRow(const std::vector<Crossing>& crossings, int row, std::uint16_t label,
             LabelVolume* volume) {
  for (std::size_t begin = 0, end = 0; begin < crossings.size(); begin = end) {
    end = begin + 1;
    while (end < crossings.size() && crossings[end].column == crossings[begin].column) ++end;
    FillBetweenCrossings(&crossings[begin], end - begin, row, label, volume);
  }
}

}  // namespace

LabelVolume VoxeliseClosedSurface(const TriangleMesh& mesh, double spacing_m, std::uint16_t label) {
  HAPTICSIM_THROW_UNLESS(std::isfinite(spacing_m) && spacing_m > 0,
                         "the voxel spacing (geometry.spacing_m) must be finite and > 0 m, not " +
                             FormatMetres(spacing_m));
  HAPTICSIM_THROW_UNLESS(label != 0, "a voxelised surface needs a label >= 1 (0 is outside)");
  CheckClosed(mesh);
  const Lattice lattice = ChooseLattice(mesh, spacing_m);

  std::vector<SnappedTriangle> triangles;
  triangles.reserve(mesh.triangles.size());
  for (const auto& triangle : mesh.triangles) {
    SnappedTriangle snapped;
    if (SnapTriangle(mesh, triangle, lattice, &snapped)) triangles.push_back(snapped);
  }
  std::vector<int> by_first_row(triangles.size());
  std::iota(by_first_row.begin(), by_first_row.end(), 0);
  std::stable_sort(by_first_row.begin(), by_first_row.end(),
                   [&](int a, int b) { return triangles[a].first_row < triangles[b].first_row; });

  LabelVolume volume;
  volume.voxels = lattice.voxels;
  volume.spacing_m = spacing_m;
  volume.origin_m = lattice.origin_m;
  volume.labels.assign(volume.num_voxels(), 0);
  std::vector<int> active;
  std::vector<Crossing> crossings;
  std::size_t next = 0;
  for (int row = 0; row < lattice.voxels[1]; ++row) {
    while (next < by_first_row.size() && triangles[by_first_row[next]].first_row <= row) {
      active.push_back(by_first_row[next++]);
    }
    active.erase(std::remove_if(active.begin(), active.end(),
                                [&](int t) { return triangles[t].last_row < row; }),
                 active.end());
    crossings.clear();
    for (int t : active) AddCrossings(triangles[t], row, &crossings);
    std::sort(crossings.begin(), crossings.end());
    FillRow(crossings, row, label, &volume);
  }
  return volume;
}

}  // namespace hapticsim
