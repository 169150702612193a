#pragma once

#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

namespace hapticsim::testing {

/**
 * Writes an ASCII STL of the closed ellipsoid with semi-axes `radii` (m) centred at `centre`:
 * `rings` latitude bands of `sectors` quads each, fans of triangles at the poles. Every vertex is
 * written from one table, so edges shared by two triangles match to the digit (a closed surface).
 */
inline void WriteEllipsoidStl(const std::string& path, const std::array<double, 3>& centre,
                              const std::array<double, 3>& radii, int rings = 24,
                              int sectors = 48) {
  using Vertex = std::array<double, 3>;
  // vertices[r][s]: ring r from the −z pole (0) to the +z pole (rings), sector s around z.
  std::vector<std::vector<Vertex>> vertices(static_cast<std::size_t>(rings) + 1);
  for (int r = 0; r <= rings; ++r) {
    const double theta = std::numbers::pi * r / rings;  // from −z
    for (int s = 0; s < sectors; ++s) {
      const double phi = 2 * std::numbers::pi * s / sectors;
      const double sin_theta = (r == 0 || r == rings) ? 0.0 : std::sin(theta);
      vertices[static_cast<std::size_t>(r)].push_back(
          {centre[0] + radii[0] * sin_theta * std::cos(phi),
           centre[1] + radii[1] * sin_theta * std::sin(phi),
           centre[2] - radii[2] * std::cos(theta)});
    }
  }
  std::FILE* out = std::fopen(path.c_str(), "w");
  if (out == nullptr) return;
  std::fprintf(out, "solid ellipsoid\n");
  const auto triangle = [&](const Vertex& a, const Vertex& b, const Vertex& c) {
    std::fprintf(out, " facet normal 0 0 0\n  outer loop\n");
    for (const Vertex* v : {&a, &b, &c}) {
      std::fprintf(out, "   vertex %.9e %.9e %.9e\n", (*v)[0], (*v)[1], (*v)[2]);
    }
    std::fprintf(out, "  endloop\n endfacet\n");
  };
  for (int r = 0; r < rings; ++r) {
    const auto& low = vertices[static_cast<std::size_t>(r)];
    const auto& high = vertices[static_cast<std::size_t>(r) + 1];
    for (int s = 0; s < sectors; ++s) {
      const auto i = static_cast<std::size_t>(s), j = static_cast<std::size_t>((s + 1) % sectors);
      // Outward by the right-hand rule; the poles' rings are one point, so one triangle there.
      if (r != 0) triangle(low[i], high[j], low[j]);
      if (r != rings - 1) triangle(low[i], high[i], high[j]);
    }
  }
  std::fprintf(out, "endsolid ellipsoid\n");
  std::fclose(out);
}

}  // namespace hapticsim::testing
