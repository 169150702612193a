#pragma once

#include <array>
#include <fstream>
#include <string>

namespace hapticsim::testing {

/** Writes an ASCII STL of the box [0, size_x] × [0, size_y] × [0, size_z] (m), 12 triangles,
 *  written by hand. */
inline void WriteBoxStl(const std::string& path, const std::array<double, 3>& size) {
  std::ofstream out(path);
  const double a = size[0], b = size[1], c = size[2];
  // Each face as two triangles (v0 v1 v2, v0 v2 v3), corners listed around the face.
  const double faces[6][4][3] = {
      {{0, 0, 0}, {0, b, 0}, {a, b, 0}, {a, 0, 0}}, {{0, 0, c}, {a, 0, c}, {a, b, c}, {0, b, c}},
      {{0, 0, 0}, {a, 0, 0}, {a, 0, c}, {0, 0, c}}, {{0, b, 0}, {0, b, c}, {a, b, c}, {a, b, 0}},
      {{0, 0, 0}, {0, 0, c}, {0, b, c}, {0, b, 0}}, {{a, 0, 0}, {a, b, 0}, {a, b, c}, {a, 0, c}}};
  out << "solid box\n";
  for (const auto& face : faces) {
    for (const auto& triangle : {std::array<int, 3>{0, 1, 2}, std::array<int, 3>{0, 2, 3}}) {
      out << " facet normal 0 0 0\n  outer loop\n";
      for (int corner : triangle) {
        out << "   vertex " << face[corner][0] << " " << face[corner][1] << " " << face[corner][2]
            << "\n";
      }
      out << "  endloop\n endfacet\n";
    }
  }
  out << "endsolid box\n";
}

/** Writes an ASCII STL of the cube [0, edge]³. */
inline void WriteBoxStl(const std::string& path, double edge) {
  WriteBoxStl(path, std::array<double, 3>{edge, edge, edge});
}

}  // namespace hapticsim::testing
