#include "daemon/contact_box.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/error.hpp"

namespace hapticsim {

std::string BoxObjectProblem(const SceneObject& object) {
  const int elements = object.field.num_elements(), occupied = object.field.num_occupied();
  if (occupied == elements) return "";
  return "hapticsimd runs objects that fill their lattice's box so far: this one leaves " +
         std::to_string(elements - occupied) + " of its " + std::to_string(elements) +
         " voxels empty (" + std::to_string(object.grid.nx() - 1) + " × " +
         std::to_string(object.grid.ny() - 1) + " × " + std::to_string(object.grid.nz() - 1) +
         "): run it offline with `hapticsim simulate`, or give a geometry that fills its box";
}

ContactBox ContactBox::Of(const Scene& scene) { return ContactBox(DescribeSceneObject(scene)); }

ContactBox::ContactBox(const SceneObject& object)
    : nodes_{object.grid.nx(), object.grid.ny(), object.grid.nz()},
      spacing_m_(object.grid.spacing()) {
  const std::string problem = BoxObjectProblem(object);
  HAPTICSIM_THROW_UNLESS(problem.empty(), problem);
  for (int c = 0; c < 3; ++c) extent_m_[c] = (nodes_[c] - 1) * spacing_m_;
  const std::size_t count = static_cast<std::size_t>(nodes_[0]) * nodes_[1] * nodes_[2];
  drivable_.assign(count, false);
  bool any_free = false;
  for (int ix = 0; ix < nodes_[0]; ++ix) {
    for (int iy = 0; iy < nodes_[1]; ++iy) {
      for (int iz = 0; iz < nodes_[2]; ++iz) {
        const LatticeIndex at{ix, iy, iz};
        if (!OnSurface(at)) continue;
        const bool held = std::binary_search(object.fixed_nodes.begin(), object.fixed_nodes.end(),
                                             object.grid.Node(ix, iy, iz));
        drivable_[Index(at)] = !held;
        any_free = any_free || !held;
      }
    }
  }
  HAPTICSIM_THROW_UNLESS(any_free, "the supports hold every surface node: nothing to touch");
}

bool ContactBox::OnSurface(const LatticeIndex& node) const noexcept {
  for (int c = 0; c < 3; ++c) {
    if (node[c] == 0 || node[c] == nodes_[c] - 1) return true;
  }
  return false;
}

bool ContactBox::Inside(const std::array<double, 3>& tip_m) const noexcept {
  bool inside = true;
  for (int c = 0; c < 3; ++c) inside = inside && tip_m[c] > 0 && tip_m[c] < extent_m_[c];
  return inside;
}

ContactBox::Entry ContactBox::EntryOf(const std::array<double, 3>& tip_m) const noexcept {
  int axis = 2;
  double face = 0, depth = tip_m[2];
  for (int c : {2, 0, 1}) {
    if (tip_m[c] < depth) depth = tip_m[c], axis = c, face = 0;
    if (extent_m_[c] - tip_m[c] < depth)
      depth = extent_m_[c] - tip_m[c], axis = c, face = extent_m_[c];
  }
  Entry entry;
  entry.point_m = tip_m;
  entry.point_m[axis] = face;
  entry.inward_normal[axis] = face == 0 ? 1.0 : -1.0;
  entry.depth_m = depth;
  return entry;
}

bool ContactBox::Drivable(const LatticeIndex& node) const noexcept {
  for (int c = 0; c < 3; ++c) {
    if (node[c] < 0 || node[c] >= nodes_[c]) return false;
  }
  return drivable_[Index(node)];
}

std::int64_t ContactBox::Code(const LatticeIndex& node) const noexcept {
  return (static_cast<std::int64_t>(node[0]) * nodes_[1] + node[1]) * nodes_[2] + node[2];
}

LatticeIndex ContactBox::Decode(std::int64_t code) const noexcept {
  const std::int64_t yz = static_cast<std::int64_t>(nodes_[1]) * nodes_[2];
  return {static_cast<int>(code / yz), static_cast<int>(code / nodes_[2] % nodes_[1]),
          static_cast<int>(code % nodes_[2])};
}

void ContactBox::ToWireIds(const std::vector<std::int32_t>& codes,
                           std::vector<std::int32_t>* wire) const {
  const std::int64_t n = wire_nodes_per_axis();
  wire->resize(codes.size());
  for (std::size_t i = 0; i < codes.size(); ++i) {
    const LatticeIndex at = Decode(codes[i]);
    (*wire)[i] = static_cast<std::int32_t>((at[0] * n + at[1]) * n + at[2]);
  }
}

std::optional<LatticeIndex> ContactBox::NearestDrivable(
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
