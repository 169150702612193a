#pragma once
// Closed surfaces built in code for the surface mesh and voxeliser tests, and the volume they
// enclose by the divergence theorem (the voxeliser's independent oracle). Test-only.

#include <array>
#include <cmath>
#include <cstddef>
#include <map>
#include <vector>

#include "core/geometry/label_volume.hpp"
#include "core/geometry/surface_mesh.hpp"

namespace hapticsim::test {

using Vec3 = std::array<double, 3>;

inline Vec3 Cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

inline double Dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/// V = Σ a · (b × c) / 6 over the triangles (a, b, c): exact for a closed, outward mesh.
inline double EnclosedVolume(const TriangleMesh& mesh) {
  double six_volume = 0;
  for (const auto& t : mesh.triangles) {
    six_volume += Dot(mesh.vertices[t[0]], Cross(mesh.vertices[t[1]], mesh.vertices[t[2]]));
  }
  return six_volume / 6;
}

/// Axis-aligned box [low, high], 8 vertices and 12 triangles wound outwards.
inline TriangleMesh Box(const Vec3& low, const Vec3& high) {
  TriangleMesh mesh;
  for (int k = 0; k < 8; ++k) {
    mesh.vertices.push_back(
        {(k & 1) ? high[0] : low[0], (k & 2) ? high[1] : low[1], (k & 4) ? high[2] : low[2]});
  }
  // Vertex k has x = bit 0, y = bit 1, z = bit 2; each face as two outward triangles.
  mesh.triangles = {{0, 2, 3}, {0, 3, 1},   // z = low
                    {4, 5, 7}, {4, 7, 6},   // z = high
                    {0, 1, 5}, {0, 5, 4},   // y = low
                    {2, 6, 7}, {2, 7, 3},   // y = high
                    {0, 4, 6}, {0, 6, 2},   // x = low
                    {1, 3, 7}, {1, 7, 5}};  // x = high
  return mesh;
}

inline TriangleMesh Tetrahedron() {
  TriangleMesh mesh;
  mesh.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  mesh.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  return mesh;
}

/// Both meshes in one (vertices renumbered).
inline TriangleMesh Joined(const TriangleMesh& a, const TriangleMesh& b) {
  TriangleMesh mesh = a;
  const int offset = static_cast<int>(a.vertices.size());
  mesh.vertices.insert(mesh.vertices.end(), b.vertices.begin(), b.vertices.end());
  for (const auto& t : b.triangles)
    mesh.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  return mesh;
}

/// Every triangle wound the other way: inward normals.
inline TriangleMesh Flipped(TriangleMesh mesh) {
  for (auto& t : mesh.triangles) std::swap(t[1], t[2]);
  return mesh;
}

/// Rotated by `angle_rad` about the axis through `centre` along z, then about the one along x.
inline TriangleMesh Rotated(TriangleMesh mesh, double angle_rad, const Vec3& centre) {
  const double c = std::cos(angle_rad), s = std::sin(angle_rad);
  for (auto& v : mesh.vertices) {
    const Vec3 d = {v[0] - centre[0], v[1] - centre[1], v[2] - centre[2]};
    const Vec3 about_z = {c * d[0] - s * d[1], s * d[0] + c * d[1], d[2]};
    const Vec3 about_x = {about_z[0], c * about_z[1] - s * about_z[2],
                          s * about_z[1] + c * about_z[2]};
    v = {centre[0] + about_x[0], centre[1] + about_x[1], centre[2] + about_x[2]};
  }
  return mesh;
}

/// An icosahedron whose faces are split in four `subdivisions` times, vertices pushed onto the
/// sphere of `radius` about `centre`; outward. 20 · 4^subdivisions triangles.
inline TriangleMesh Icosphere(double radius, int subdivisions, const Vec3& centre) {
  const double g = (1 + std::sqrt(5.0)) / 2;
  std::vector<Vec3> unit = {{-1, g, 0}, {1, g, 0}, {-1, -g, 0}, {1, -g, 0},
                            {0, -1, g}, {0, 1, g}, {0, -1, -g}, {0, 1, -g},
                            {g, 0, -1}, {g, 0, 1}, {-g, 0, -1}, {-g, 0, 1}};
  std::vector<std::array<int, 3>> faces = {
      {0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
      {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
      {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  auto normalised = [](const Vec3& v) {
    const double length = std::sqrt(Dot(v, v));
    return Vec3{v[0] / length, v[1] / length, v[2] / length};
  };
  for (auto& v : unit) v = normalised(v);
  for (int level = 0; level < subdivisions; ++level) {
    std::map<std::pair<int, int>, int> midpoint_of_edge;
    auto midpoint = [&](int a, int b) {
      const auto key = std::make_pair(std::min(a, b), std::max(a, b));
      if (const auto found = midpoint_of_edge.find(key); found != midpoint_of_edge.end()) {
        return found->second;
      }
      unit.push_back(
          normalised({unit[a][0] + unit[b][0], unit[a][1] + unit[b][1], unit[a][2] + unit[b][2]}));
      return midpoint_of_edge[key] = static_cast<int>(unit.size()) - 1;
    };
    std::vector<std::array<int, 3>> finer;
    for (const auto& f : faces) {
      const int ab = midpoint(f[0], f[1]), bc = midpoint(f[1], f[2]), ca = midpoint(f[2], f[0]);
      finer.insert(finer.end(), {{f[0], ab, ca}, {f[1], bc, ab}, {f[2], ca, bc}, {ab, bc, ca}});
    }
    faces = std::move(finer);
  }
  TriangleMesh mesh;
  for (const auto& v : unit) {
    mesh.vertices.push_back(
        {centre[0] + radius * v[0], centre[1] + radius * v[1], centre[2] + radius * v[2]});
  }
  mesh.triangles = faces;
  return mesh;
}

/// A torus about the z axis through `centre`: tube radius `minor` at distance `major`, `around`
/// × `across` quads split in two; outward.
inline TriangleMesh Torus(double major, double minor, int around, int across, const Vec3& centre) {
  const double pi = std::acos(-1.0);
  TriangleMesh mesh;
  for (int i = 0; i < around; ++i) {
    const double u = 2 * pi * i / around;
    for (int j = 0; j < across; ++j) {
      const double v = 2 * pi * j / across;
      const double ring = major + minor * std::cos(v);
      mesh.vertices.push_back({centre[0] + ring * std::cos(u), centre[1] + ring * std::sin(u),
                               centre[2] + minor * std::sin(v)});
    }
  }
  auto at = [&](int i, int j) { return (i % around) * across + (j % across); };
  for (int i = 0; i < around; ++i) {
    for (int j = 0; j < across; ++j) {
      mesh.triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      mesh.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  }
  return mesh;
}

inline std::size_t CountLabelled(const LabelVolume& volume) {
  std::size_t count = 0;
  for (auto label : volume.labels) count += label != 0;
  return count;
}

inline double LabelledVolume(const LabelVolume& volume) {
  return static_cast<double>(CountLabelled(volume)) * std::pow(volume.spacing_m, 3);
}

}  // namespace hapticsim::test
