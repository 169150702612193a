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
  std::vector<LatticeIndex> free;
  for (int ix = 0; ix < nodes_[0]; ++ix) {
    for (int iy = 0; iy < nodes_[1]; ++iy) {
      for (int iz = 0; iz < nodes_[2]; ++iz) {
        const LatticeIndex at{ix, iy, iz};
        if (!OnSurface(at)) continue;
        const bool held = std::binary_search(object.fixed_nodes.begin(), object.fixed_nodes.end(),
                                             object.grid.Node(ix, iy, iz));
        drivable_[Index(at)] = !held;
        if (!held) free.push_back(at);
      }
    }
  }
  HAPTICSIM_THROW_UNLESS(!free.empty(), "the supports hold every surface node: nothing to touch");
  // Each held surface node's stand-in: the drivable node nearest to it (ties to the lower code).
  substitute_.assign(count, -1);
  for (std::size_t i = 0; i < count; ++i) {
    const LatticeIndex at = Decode(static_cast<std::int64_t>(i));
    if (drivable_[i] || !OnSurface(at)) continue;
    long best = std::numeric_limits<long>::max();
    for (const LatticeIndex& f : free) {
      long d2 = 0;
      for (int c = 0; c < 3; ++c) d2 += static_cast<long>(f[c] - at[c]) * (f[c] - at[c]);
      if (d2 < best) best = d2, substitute_[i] = static_cast<std::int32_t>(Code(f));
    }
  }
}

bool ContactBox::OnSurface(const LatticeIndex& node) const noexcept {
  for (int c = 0; c < 3; ++c) {
    if (node[c] == 0 || node[c] == nodes_[c] - 1) return true;
  }
  return false;
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

LatticeIndex ContactBox::NearestDrivable(
    const std::array<double, 3>& surface_point_m) const noexcept {
  LatticeIndex node{};
  std::array<double, 3> at{};  // the point in lattice units
  for (int c = 0; c < 3; ++c) {
    at[c] = surface_point_m[c] / spacing_m_;
    node[c] = std::clamp(static_cast<int>(std::lround(at[c])), 0, nodes_[c] - 1);
  }
  if (drivable_[Index(node)]) return node;
  // Held (a support): its drivable neighbour on the surface nearest to the point, so a touch
  // beside a held corner picks the node on the side it came down on.
  LatticeIndex best = node;
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
  if (best != node) return best;
  return Decode(substitute_[Index(node)]);
}

}  // namespace hapticsim
