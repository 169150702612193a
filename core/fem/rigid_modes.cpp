#include "core/fem/rigid_modes.hpp"

#include <array>
#include <cstdint>
#include <cstdio>
#include <algorithm>
#include <numeric>

namespace hapticsim {
namespace {

// Union-find over the occupied elements, joined through shared faces.
class FaceConnectedParts {
 public:
  FaceConnectedParts(const HexGrid& grid, const MaterialField& field)
      : parent_(static_cast<std::size_t>(field.num_elements())) {
    std::iota(parent_.begin(), parent_.end(), 0);
    const int ex = grid.nx() - 1, ey = grid.ny() - 1, ez = grid.nz() - 1;
    for (int z = 0; z < ez; ++z) {
      for (int y = 0; y < ey; ++y) {
        for (int x = 0; x < ex; ++x) {
          const int e = field.Element(x, y, z);
          if (!field.occupied(e)) continue;
          if (x + 1 < ex && field.occupied(e + 1)) Join(e, e + 1);
          if (y + 1 < ey && field.occupied(field.Element(x, y + 1, z))) {
            Join(e, field.Element(x, y + 1, z));
          }
          if (z + 1 < ez && field.occupied(field.Element(x, y, z + 1))) {
            Join(e, field.Element(x, y, z + 1));
          }
        }
      }
    }
  }
  int Root(int e) {
    while (parent_[static_cast<std::size_t>(e)] != e) {
      int& up = parent_[static_cast<std::size_t>(e)];
      up = parent_[static_cast<std::size_t>(up)];
      e = up;
    }
    return e;
  }

 private:
  void Join(int a, int b) { parent_[static_cast<std::size_t>(Root(a))] = Root(b); }
  std::vector<int> parent_;
};

// Whether the held lattice points of one part include three that are not on one line; exact in
// integers (lattice indices).
class NonCollinearWitness {
 public:
  void Add(const std::array<int, 3>& p) {
    if (!has_first_) {
      first_ = p;
      has_first_ = true;
    } else if (!has_second_) {
      if (p != first_) {
        second_ = p;
        has_second_ = true;
      }
    } else if (!spans_plane_) {
      const std::array<long, 3> a = Minus(second_, first_), b = Minus(p, first_);
      spans_plane_ = a[1] * b[2] != a[2] * b[1] || a[2] * b[0] != a[0] * b[2] ||
                     a[0] * b[1] != a[1] * b[0];
    }
  }
  bool spans_plane() const { return spans_plane_; }

 private:
  static std::array<long, 3> Minus(const std::array<int, 3>& p, const std::array<int, 3>& q) {
    return {long{p[0]} - q[0], long{p[1]} - q[1], long{p[2]} - q[2]};
  }
  std::array<int, 3> first_{}, second_{};
  bool has_first_ = false, has_second_ = false, spans_plane_ = false;
};

std::string DescribeFreePart(const HexGrid& grid, const std::vector<int>& nodes, int elements,
                             int held_nodes) {
  std::array<double, 3> centre{};
  for (int node : nodes) {
    const auto at = grid.NodePosition(node);
    for (int c = 0; c < 3; ++c) centre[c] += at[c] / static_cast<double>(nodes.size());
  }
  char text[320];
  std::snprintf(text, sizeof text,
                "the part of the object of %d elements around (%.4g, %.4g, %.4g) m is held at "
                "%d node%s: it could move as a rigid body. Hold at least three of its nodes that "
                "are not on one line (a support by label, box or plane)",
                elements, centre[0], centre[1], centre[2], held_nodes, held_nodes == 1 ? "" : "s");
  return text;
}

// The face-connected parts: each one's nodes (with repeats, which do not change whether three of
// them span a plane) and its element count.
struct Parts {
  std::vector<std::vector<int>> nodes;
  std::vector<int> elements;
};

Parts CollectParts(const HexGrid& grid, const MaterialField& field) {
  FaceConnectedParts union_find(grid, field);
  std::vector<int> part_of_root(static_cast<std::size_t>(field.num_elements()), -1);
  Parts parts;
  for (int z = 0; z + 1 < grid.nz(); ++z) {
    for (int y = 0; y + 1 < grid.ny(); ++y) {
      for (int x = 0; x + 1 < grid.nx(); ++x) {
        const int e = field.Element(x, y, z);
        if (!field.occupied(e)) continue;
        int& part = part_of_root[static_cast<std::size_t>(union_find.Root(e))];
        if (part < 0) {
          part = static_cast<int>(parts.nodes.size());
          parts.nodes.emplace_back();
          parts.elements.push_back(0);
        }
        ++parts.elements[static_cast<std::size_t>(part)];
        for (int node : grid.ElementNodes(x, y, z)) {
          parts.nodes[static_cast<std::size_t>(part)].push_back(node);
        }
      }
    }
  }
  return parts;
}

}  // namespace

std::string RigidBodyModeProblem(const HexGrid& grid, const MaterialField& field,
                                 const std::vector<int>& fixed_nodes) {
  field.CheckFits(grid);
  const Parts parts = CollectParts(grid, field);
  const std::vector<std::vector<int>>& part_nodes = parts.nodes;
  const std::vector<int>& part_elements = parts.elements;
  std::vector<std::uint8_t> held(static_cast<std::size_t>(grid.num_nodes()), 0);
  for (int node : fixed_nodes) held[static_cast<std::size_t>(node)] = 1;
  std::vector<bool> part_held(part_nodes.size(), false);
  for (bool changed = true; changed;) {
    changed = false;
    for (std::size_t p = 0; p < part_nodes.size(); ++p) {
      if (part_held[p]) continue;
      NonCollinearWitness witness;
      for (int node : part_nodes[p]) {
        if (held[static_cast<std::size_t>(node)]) witness.Add(grid.NodeIndices(node));
      }
      if (!witness.spans_plane()) continue;
      part_held[p] = changed = true;
      for (int node : part_nodes[p]) held[static_cast<std::size_t>(node)] = 1;
    }
  }
  for (std::size_t p = 0; p < part_nodes.size(); ++p) {
    if (part_held[p]) continue;
    std::vector<int> distinct_held;
    for (int node : part_nodes[p]) {
      if (held[static_cast<std::size_t>(node)]) distinct_held.push_back(node);
    }
    std::sort(distinct_held.begin(), distinct_held.end());
    distinct_held.erase(std::unique(distinct_held.begin(), distinct_held.end()),
                        distinct_held.end());
    return DescribeFreePart(grid, part_nodes[p], part_elements[p],
                            static_cast<int>(distinct_held.size()));
  }
  return "";
}

}  // namespace hapticsim
