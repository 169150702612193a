#include "core/scene/support_regions.hpp"

#include <algorithm>
#include <cmath>

#include "core/error.hpp"

namespace hapticsim {
namespace {

bool Finite(const std::array<double, 3>& v) {
  return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]);
}

// Per node: whether the table holds it.
std::vector<bool> Holds(const SupportRegion& support, const ObjectLattice& object) {
  const HexGrid& grid = object.grid;
  std::vector<bool> held(static_cast<std::size_t>(grid.num_nodes()), false);
  if (support.kind == SupportRegion::Kind::kLabel) {
    for (int z = 0; z + 1 < grid.nz(); ++z) {
      for (int y = 0; y + 1 < grid.ny(); ++y) {
        for (int x = 0; x + 1 < grid.nx(); ++x) {
          const int label = object.labels ? object.labels->at(x, y, z)
                            : object.field.occupied(object.field.Element(x, y, z)) ? 1
                                                                                   : 0;
          if (label != support.label) continue;
          for (int node : grid.ElementNodes(x, y, z)) held[static_cast<std::size_t>(node)] = true;
        }
      }
    }
    return held;
  }
  const double h = grid.spacing(), tolerance = 1e-9 * h;
  std::array<double, 3> unit = support.normal;
  const double length = std::hypot(unit[0], unit[1], unit[2]);
  for (double& c : unit) c /= length;
  for (int node = 0; node < grid.num_nodes(); ++node) {
    std::array<double, 3> p = grid.NodePosition(node);
    for (int c = 0; c < 3; ++c) p[c] += object.origin_m[c];
    if (support.kind == SupportRegion::Kind::kBox) {
      bool inside = true;
      for (int c = 0; c < 3; ++c) {
        inside = inside && p[c] >= support.box_min_m[c] - tolerance &&
                 p[c] <= support.box_max_m[c] + tolerance;
      }
      held[static_cast<std::size_t>(node)] = inside;
    } else {
      double distance = 0;
      for (int c = 0; c < 3; ++c) distance += (p[c] - support.point_m[c]) * unit[c];
      held[static_cast<std::size_t>(node)] = std::abs(distance) <= 0.5 * h + tolerance;
    }
  }
  return held;
}

}  // namespace

std::string SupportTableName(const SupportRegion& support, std::size_t index) {
  const char* kind = support.kind == SupportRegion::Kind::kLabel ? "label"
                     : support.kind == SupportRegion::Kind::kBox ? "box"
                                                                 : "plane";
  return "[[support]] " + std::to_string(index + 1) + " (" + kind + ")";
}

void ValidateSupportRegions(const std::vector<SupportRegion>& supports) {
  for (std::size_t i = 0; i < supports.size(); ++i) {
    const SupportRegion& s = supports[i];
    const std::string name = SupportTableName(s, i);
    switch (s.kind) {
      case SupportRegion::Kind::kLabel:
        HAPTICSIM_THROW_UNLESS(s.label >= 1 && s.label <= 65535,
                               name + ": label = " + std::to_string(s.label) +
                                   " must be a whole number from 1 to 65535");
        break;
      case SupportRegion::Kind::kBox:
        HAPTICSIM_THROW_UNLESS(Finite(s.box_min_m) && Finite(s.box_max_m),
                               name + ": box_min and box_max must be finite (m)");
        for (int c = 0; c < 3; ++c) {
          HAPTICSIM_THROW_UNLESS(s.box_min_m[c] <= s.box_max_m[c],
                                 name + ": box_min = " + FormatTriple(s.box_min_m) +
                                     " must not exceed box_max = " + FormatTriple(s.box_max_m) +
                                     " on any axis (m)");
        }
        break;
      case SupportRegion::Kind::kPlane:
        HAPTICSIM_THROW_UNLESS(Finite(s.point_m) && Finite(s.normal),
                               name + ": plane_point and plane_normal must be finite");
        HAPTICSIM_THROW_UNLESS(std::hypot(s.normal[0], s.normal[1], s.normal[2]) > 0,
                               name + ": plane_normal = " + FormatTriple(s.normal) +
                                   " must not be zero");
        break;
    }
  }
}

std::vector<int> SelectSupportNodes(const std::vector<SupportRegion>& supports,
                                    const ObjectLattice& object) {
  ValidateSupportRegions(supports);
  const std::vector<bool> active = object.field.ActiveNodes(object.grid);
  std::vector<bool> held_by_any(active.size(), false);
  for (std::size_t i = 0; i < supports.size(); ++i) {
    const std::vector<bool> held = Holds(supports[i], object);
    bool holds_some = false;
    for (std::size_t node = 0; node < held.size(); ++node) {
      if (!held[node] || !active[node]) continue;
      held_by_any[node] = holds_some = true;
    }
    HAPTICSIM_THROW_UNLESS(holds_some, SupportTableName(supports[i], i) +
                                           " holds no node of the object: check its label or "
                                           "coordinates against the geometry's frame (m)");
  }
  std::vector<int> nodes;
  for (std::size_t node = 0; node < held_by_any.size(); ++node) {
    if (held_by_any[node]) nodes.push_back(static_cast<int>(node));
  }
  return nodes;
}

}  // namespace hapticsim
