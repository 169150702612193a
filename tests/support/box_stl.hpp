#pragma once

#include <array>
#include <fstream>
#include <string>

namespace hapticsim::testing {

/** Writes an ASCII STL of the box [0, edge]³, 12 triangles, written by hand. */
inline void WriteBoxStl(const std::string& path, double edge) {
  std::ofstream out(path);
  const double e = edge;
  // Each face as two triangles (v0 v1 v2, v0 v2 v3), corners listed around the face.
  const double faces[6][4][3] = {
      {{0, 0, 0}, {0, e, 0}, {e, e, 0}, {e, 0, 0}}, {{0, 0, e}, {e, 0, e}, {e, e, e}, {0, e, e}},
      {{0, 0, 0}, {e, 0, 0}, {e, 0, e}, {0, 0, e}}, {{0, e, 0}, {0, e, e}, {e, e, e}, {e, e, 0}},
      {{0, 0, 0}, {0, 0, e}, {0, e, e}, {0, e, 0}}, {{e, 0, 0}, {e, e, 0}, {e, e, e}, {e, 0, e}}};
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

}  // namespace hapticsim::testing
