#include "daemon/contact_object.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/error.hpp"

namespace hapticsim {

namespace {

constexpr double Clamp(double x, double lo, double hi) { return x < lo ? lo : (x > hi ? hi : x); }

}  // namespace

ContactObject ContactObject::Of(const Scene& scene) {
  return ContactObject(DescribeSceneObject(scene));
}

ContactObject::ContactObject(const SceneObject& object)
    : nodes_{object.grid.nx(), object.grid.ny(), object.grid.nz()},
      spacing_m_(object.grid.spacing()) {
  for (int c = 0; c < 3; ++c) extent_m_[c] = (nodes_[c] - 1) * spacing_m_;
  const int vx = nodes_[0] - 1, vy = nodes_[1] - 1, vz = nodes_[2] - 1;
  occupied_.assign(static_cast<std::size_t>(vx) * vy * vz, false);
  for (int z = 0; z < vz; ++z) {
    for (int y = 0; y < vy; ++y) {
      for (int x = 0; x < vx; ++x) {
        const bool occupied = object.field.occupied(object.field.Element(x, y, z));
        occupied_[static_cast<std::size_t>(x + vx * (y + vy * z))] = occupied;
        occupied_voxels_ += occupied ? 1 : 0;
      }
    }
  }
  const std::size_t count = static_cast<std::size_t>(nodes_[0]) * nodes_[1] * nodes_[2];
  drivable_.assign(count, false);
  flat_face_.assign(count, 0);
  for (int ix = 0; ix < nodes_[0]; ++ix) {
    for (int iy = 0; iy < nodes_[1]; ++iy) {
      for (int iz = 0; iz < nodes_[2]; ++iz) {
        const LatticeIndex at{ix, iy, iz};
        const int node = object.grid.Node(ix, iy, iz);
        if (!IsObjectSurfaceNode(object.grid, object.field, node)) continue;
        const bool held =
            std::binary_search(object.fixed_nodes.begin(), object.fixed_nodes.end(), node);
        drivable_[Index(at)] = !held;
        drivable_nodes_ += held ? 0 : 1;
        flat_face_[Index(at)] = FlatFaceCode(at);
      }
    }
  }
  HAPTICSIM_THROW_UNLESS(drivable_nodes_ > 0,
                         "the supports hold every surface node: nothing to touch");
  FloodNearestVoxels();
}

bool ContactObject::Occupied(int vx, int vy, int vz) const noexcept {
  const int nx = nodes_[0] - 1, ny = nodes_[1] - 1, nz = nodes_[2] - 1;
  if (vx < 0 || vy < 0 || vz < 0 || vx >= nx || vy >= ny || vz >= nz) return false;
  return occupied_[static_cast<std::size_t>(vx + nx * (vy + ny * vz))];
}

std::int8_t ContactObject::FlatFaceCode(const LatticeIndex& node) const noexcept {
  // The eight voxels around the node, by their offset d ∈ {−1, 0}³ from it: flat when the four
  // on one side of an axis plane (d[axis] = 0: the +axis side) are occupied and the rest empty.
  for (int axis = 0; axis < 3; ++axis) {
    for (int side : {-1, 0}) {
      bool flat = true;
      for (int d = 0; d < 8 && flat; ++d) {
        const std::array<int, 3> off{-(d & 1), -((d >> 1) & 1), -((d >> 2) & 1)};
        const bool occupied = Occupied(node[0] + off[0], node[1] + off[1], node[2] + off[2]);
        flat = occupied == (off[axis] == side);
      }
      if (flat) return static_cast<std::int8_t>(side == 0 ? axis + 1 : -(axis + 1));
    }
  }
  return 0;
}

void ContactObject::FloodNearestVoxels() {
  // A breadth-first flood from every occupied voxel over the lattice's 26-neighbourhood: each
  // empty voxel takes the voxel the flood reached it from (near enough to the nearest, which is
  // all a hovering tool needs: which node the regions should get ready on).
  const int nx = nodes_[0] - 1, ny = nodes_[1] - 1, nz = nodes_[2] - 1;
  nearest_.assign(occupied_.size(), -1);
  std::vector<std::int32_t> queue;
  queue.reserve(occupied_.size());
  for (std::size_t v = 0; v < occupied_.size(); ++v) {
    if (occupied_[v]) nearest_[v] = static_cast<std::int32_t>(v), queue.push_back(nearest_[v]);
  }
  for (std::size_t head = 0; head < queue.size(); ++head) {
    const int v = queue[head], x = v % nx, y = v / nx % ny, z = v / (nx * ny);
    for (int dz = -1; dz <= 1; ++dz) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const int ax = x + dx, ay = y + dy, az = z + dz;
          if (ax < 0 || ay < 0 || az < 0 || ax >= nx || ay >= ny || az >= nz) continue;
          const std::size_t next = static_cast<std::size_t>(ax + nx * (ay + ny * az));
          if (nearest_[next] >= 0) continue;
          nearest_[next] = nearest_[static_cast<std::size_t>(v)];
          queue.push_back(static_cast<std::int32_t>(next));
        }
      }
    }
  }
}

std::array<int, 3> ContactObject::VoxelOf(const std::array<double, 3>& point_m) const noexcept {
  std::array<int, 3> voxel{};
  for (int c = 0; c < 3; ++c) {
    const double at = std::floor(Clamp(point_m[c], 0.0, extent_m_[c]) / spacing_m_);
    voxel[c] = std::clamp(static_cast<int>(at), 0, nodes_[c] - 2);
  }
  return voxel;
}

bool ContactObject::Inside(const std::array<double, 3>& tip_m) const noexcept {
  bool inside = true;
  for (int c = 0; c < 3; ++c) inside = inside && tip_m[c] > 0 && tip_m[c] < extent_m_[c];
  if (!inside) return false;
  const std::array<int, 3> v = VoxelOf(tip_m);
  return Occupied(v[0], v[1], v[2]);
}

std::array<ContactObject::Entry, 6> ContactObject::WaysOutFrom(
    const std::array<double, 3>& point_m, const std::array<int, 3>& voxel) const noexcept {
  // Along each axis the row of occupied voxels through `voxel` ends, on either side, at a face
  // of the surface: those six faces, −z (the front) first, then +z, −x, +x, −y, +y, each with the
  // point projected onto it, sorted by depth keeping that order on a tie (by hand: six entries,
  // and the primary thread asks).
  const auto face_beyond_row = [&](int c, int step) {
    std::array<int, 3> at = voxel;
    do {
      at[c] += step;
    } while (Occupied(at[0], at[1], at[2]));
    return (step < 0 ? at[c] + 1 : at[c]) * spacing_m_;
  };
  std::array<Entry, 6> ways{};
  int count = 0;
  for (int c : {2, 0, 1}) {
    for (int step : {-1, +1}) {
      Entry way;
      const double face = face_beyond_row(c, step);
      way.point_m = point_m;
      way.point_m[c] = face;
      way.inward_normal[c] = -step;
      way.depth_m = step < 0 ? point_m[c] - face : face - point_m[c];
      int at = count++;
      for (; at > 0 && ways[at - 1].depth_m > way.depth_m; --at) ways[at] = ways[at - 1];
      ways[at] = way;
    }
  }
  return ways;
}

ContactObject::Entry ContactObject::EntryFrom(const std::array<double, 3>& point_m,
                                              const std::array<int, 3>& voxel) const noexcept {
  return WaysOutFrom(point_m, voxel)[0];  // the nearest of the six faces is the way in
}

ContactObject::Entry ContactObject::EntryOf(const std::array<double, 3>& tip_m) const noexcept {
  return EntryFrom(tip_m, VoxelOf(tip_m));
}

std::array<ContactObject::Entry, 6> ContactObject::WaysOut(
    const std::array<double, 3>& tip_m) const noexcept {
  return WaysOutFrom(tip_m, VoxelOf(tip_m));
}

std::array<int, 3> ContactObject::NearestVoxel(
    const std::array<double, 3>& point_m) const noexcept {
  const std::array<int, 3> v = VoxelOf(point_m);
  const int nx = nodes_[0] - 1, ny = nodes_[1] - 1;
  const std::int32_t flooded = nearest_[static_cast<std::size_t>(v[0] + nx * (v[1] + ny * v[2]))];
  // The flood's voxel is near the nearest, not always it (it measures in steps, not metres): the
  // nearest among the voxels around it and around the point's own voxel.
  std::array<int, 3> best{flooded % nx, flooded / nx % ny, flooded / (nx * ny)};
  double best_d2 = std::numeric_limits<double>::infinity();
  for (const std::array<int, 3> around : {best, v}) {
    for (int d = 0; d < 27; ++d) {
      const std::array<int, 3> at{around[0] + d % 3 - 1, around[1] + d / 3 % 3 - 1,
                                  around[2] + d / 9 - 1};
      if (!Occupied(at[0], at[1], at[2])) continue;
      double d2 = 0;
      for (int c = 0; c < 3; ++c) {
        const double gap =
            point_m[c] - Clamp(point_m[c], at[c] * spacing_m_, (at[c] + 1) * spacing_m_);
        d2 += gap * gap;
      }
      if (d2 < best_d2) best_d2 = d2, best = at;
    }
  }
  return best;
}

std::array<double, 3> ContactObject::PointOf(const std::array<int, 3>& voxel,
                                             const std::array<double, 3>& tip_m) const noexcept {
  std::array<double, 3> point{};
  for (int c = 0; c < 3; ++c) {
    point[c] = Clamp(tip_m[c], voxel[c] * spacing_m_, (voxel[c] + 1) * spacing_m_);
  }
  return point;
}

std::array<double, 3> ContactObject::NearestPoint(
    const std::array<double, 3>& tip_m) const noexcept {
  if (Inside(tip_m)) return tip_m;
  return PointOf(NearestVoxel(tip_m), tip_m);
}

ContactObject::Entry ContactObject::HoverEntry(const std::array<double, 3>& tip_m) const noexcept {
  if (Inside(tip_m)) return EntryOf(tip_m);
  const std::array<int, 3> voxel = NearestVoxel(tip_m);
  return EntryFrom(PointOf(voxel, tip_m), voxel);
}

std::array<double, 3> ContactObject::FlatFaceNormal(const LatticeIndex& node) const noexcept {
  std::array<double, 3> normal{};
  for (int c = 0; c < 3; ++c) {
    if (node[c] < 0 || node[c] >= nodes_[c]) return normal;
  }
  const int code = flat_face_[Index(node)];
  if (code != 0) normal[std::abs(code) - 1] = code > 0 ? 1.0 : -1.0;
  return normal;
}

bool ContactObject::Drivable(const LatticeIndex& node) const noexcept {
  for (int c = 0; c < 3; ++c) {
    if (node[c] < 0 || node[c] >= nodes_[c]) return false;
  }
  return drivable_[Index(node)];
}

std::int64_t ContactObject::Code(const LatticeIndex& node) const noexcept {
  return (static_cast<std::int64_t>(node[0]) * nodes_[1] + node[1]) * nodes_[2] + node[2];
}

LatticeIndex ContactObject::Decode(std::int64_t code) const noexcept {
  const std::int64_t yz = static_cast<std::int64_t>(nodes_[1]) * nodes_[2];
  return {static_cast<int>(code / yz), static_cast<int>(code / nodes_[2] % nodes_[1]),
          static_cast<int>(code % nodes_[2])};
}

void ContactObject::ToWireIds(const std::vector<std::int32_t>& codes,
                              std::vector<std::int32_t>* wire) const {
  const std::int64_t n = wire_nodes_per_axis();
  wire->resize(codes.size());
  for (std::size_t i = 0; i < codes.size(); ++i) {
    const LatticeIndex at = Decode(codes[i]);
    (*wire)[i] = static_cast<std::int32_t>((at[0] * n + at[1]) * n + at[2]);
  }
}

std::optional<LatticeIndex> ContactObject::NearestDrivable(
    const std::array<double, 3>& surface_point_m) const noexcept {
  LatticeIndex node{};
  std::array<double, 3> at{};  // the point in lattice units
  for (int c = 0; c < 3; ++c) {
    at[c] = surface_point_m[c] / spacing_m_;
    node[c] = std::clamp(static_cast<int>(std::lround(at[c])), 0, nodes_[c] - 1);
  }
  if (drivable_[Index(node)]) return node;
  std::optional<LatticeIndex> best;
  double best_d2 = std::numeric_limits<double>::infinity();
  for (int axis = 0; axis < 3; ++axis) {
    for (int step : {-1, 1}) {
      LatticeIndex next = node;
      next[axis] += step;
      if (!Drivable(next)) continue;
      double d2 = 0;
      for (int c = 0; c < 3; ++c) d2 += (at[c] - next[c]) * (at[c] - next[c]);
      if (d2 < best_d2) best_d2 = d2, best = next;
    }
  }
  return best;
}

}  // namespace hapticsim
