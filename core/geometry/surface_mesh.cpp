#include "core/geometry/surface_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <numeric>
#include <sstream>
#include <string>

#include "core/error.hpp"

namespace hapticsim {
namespace {

/// Edge uses are numbered 3 · triangle + slot in an int.
constexpr std::size_t kMaxTriangles = 700'000'000;

std::string FormatPoint(const std::array<double, 3>& point) {
  std::ostringstream out;
  out.precision(7);
  out << '(' << point[0] << ", " << point[1] << ", " << point[2] << ") m";
  return out.str();
}

void CheckVerticesAndIndices(const TriangleMesh& mesh) {
  HAPTICSIM_THROW_UNLESS(!mesh.triangles.empty(),
                         "the surface mesh has no triangles: it bounds no volume");
  HAPTICSIM_THROW_UNLESS(mesh.triangles.size() <= kMaxTriangles,
                         "the surface mesh has " + std::to_string(mesh.triangles.size()) +
                             " triangles, more than the " + std::to_string(kMaxTriangles) +
                             " hapticsim reads: decimate it in your modeller");
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
    const auto& p = mesh.vertices[v];
    HAPTICSIM_THROW_UNLESS(std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]),
                           "surface mesh vertex " + std::to_string(v) +
                               " has a coordinate that is not finite: " + FormatPoint(p));
  }
  const long long num_vertices = static_cast<long long>(mesh.vertices.size());
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    for (int corner : mesh.triangles[t]) {
      HAPTICSIM_THROW_UNLESS(corner >= 0 && corner < num_vertices,
                             "surface mesh triangle " + std::to_string(t) + " refers to vertex " +
                                 std::to_string(corner) + ", but the mesh has " +
                                 std::to_string(num_vertices) + " vertices (0 to " +
                                 std::to_string(num_vertices - 1) + ")");
    }
  }
}

/// For each vertex, the lowest index of a vertex at exactly its position: edges are matched by
/// position, not index, since an STL stores every triangle's corners apart. Lexicographic `<`
/// on doubles makes -0 and +0 one position (the vertices are finite here).
std::vector<int> JoinByPosition(const std::vector<std::array<double, 3>>& vertices) {
  std::vector<int> order(vertices.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return vertices[a] < vertices[b]; });
  std::vector<int> joined(vertices.size());
  for (std::size_t k = 0; k < order.size(); ++k) {
    const bool same_as_previous = k > 0 && !(vertices[order[k - 1]] < vertices[order[k]]);
    joined[order[k]] = same_as_previous ? joined[order[k - 1]] : order[k];
  }
  return joined;
}

/// Refuses a triangle with two corners at one position: it has no area and no direction, and
/// is most likely an exporter's leftover. (The reader drops these; a mesh built in code must
/// not have them.) Three distinct but collinear corners are accepted: such a sliver keeps every
/// edge count right and the voxeliser's exact predicates never count a crossing through it.
void CheckNoRepeatedCorner(const TriangleMesh& mesh, const std::vector<int>& joined) {
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tri = mesh.triangles[t];
    const int a = joined[tri[0]], b = joined[tri[1]], c = joined[tri[2]];
    if (a != b && b != c && c != a) continue;
    const int repeated = (a == b || a == c) ? a : b;
    throw Error("surface mesh triangle " + std::to_string(t) +
                " has two corners at the same position " + FormatPoint(mesh.vertices[repeated]) +
                ": it has no area. Remove it (or merge the vertices) in your modeller");
  }
}

struct EdgeUse {
  int low, high;  ///< joined end points, low < high: the undirected edge
  int use;        ///< 3 · triangle + edge slot: where the edge is used, in the mesh's order
  bool operator<(const EdgeUse& other) const {
    if (low != other.low) return low < other.low;
    if (high != other.high) return high < other.high;
    return use < other.use;
  }
};

std::vector<EdgeUse> SortedEdgeUses(const TriangleMesh& mesh, const std::vector<int>& joined) {
  std::vector<EdgeUse> uses;
  uses.reserve(3 * mesh.triangles.size());
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    for (int slot = 0; slot < 3; ++slot) {
      const int from = joined[mesh.triangles[t][slot]];
      const int to = joined[mesh.triangles[t][(slot + 1) % 3]];
      uses.push_back({std::min(from, to), std::max(from, to), static_cast<int>(3 * t) + slot});
    }
  }
  std::sort(uses.begin(), uses.end());
  return uses;
}

}  // namespace

void CheckClosed(const TriangleMesh& mesh) {
  CheckVerticesAndIndices(mesh);
  const std::vector<int> joined = JoinByPosition(mesh.vertices);
  CheckNoRepeatedCorner(mesh, joined);
  const std::vector<EdgeUse> uses = SortedEdgeUses(mesh, joined);
  std::size_t open = 0, over_shared = 0;
  int first_bad_use = -1;
  for (std::size_t begin = 0, end = 0; begin < uses.size(); begin = end) {
    end = begin + 1;
    while (end < uses.size() && uses[end].low == uses[begin].low &&
           uses[end].high == uses[begin].high) {
      ++end;
    }
    const std::size_t triangles_on_edge = end - begin;
    if (triangles_on_edge == 2) continue;
    ++(triangles_on_edge == 1 ? open : over_shared);
    // uses[begin] is the edge's first use in the mesh's order, as `use` sorts last.
    if (first_bad_use < 0 || uses[begin].use < first_bad_use) first_bad_use = uses[begin].use;
  }
  if (first_bad_use < 0) return;
  const auto& triangle = mesh.triangles[first_bad_use / 3];
  const int slot = first_bad_use % 3;
  throw Error("the surface mesh is not closed: " + std::to_string(open) +
              " edges are open (on one triangle only) and " + std::to_string(over_shared) +
              " are shared by more than two triangles; the first, on triangle " +
              std::to_string(first_bad_use / 3) + ", runs from " +
              FormatPoint(mesh.vertices[triangle[slot]]) + " to " +
              FormatPoint(mesh.vertices[triangle[(slot + 1) % 3]]) +
              ". A mesh to voxelise must bound a volume: close the holes (or split the edges "
              "three or more faces share) in your modeller");
}

}  // namespace hapticsim
