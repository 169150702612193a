#pragma once

#include <string>

#include "core/geometry/surface_mesh.hpp"

namespace hapticsim {

/**
 * Reads a triangulated surface from an STL (ASCII or binary) or OBJ file, vertices joined by
 * exact position, coordinates multiplied by `metres_per_unit` (0.001 for a mesh drawn in
 * millimetres). Assimp reads the file, so coordinates pass through single precision. Polygons
 * are split into triangles; triangles with two corners at one position are dropped (they bound
 * nothing, and dropping one never opens the surface). The format is chosen by the extension
 * (.stl or .obj, any case); an ASCII STL must follow the usual grammar, one statement a line.
 * Nothing is printed, and no other file (an OBJ's material library) is opened.
 * @throws Error naming the file and what is wrong: unreadable, not STL or OBJ, truncated, no
 *         triangles, a point or line, a vertex index out of range, a coordinate that is not
 *         finite, or `metres_per_unit` not finite and > 0.
 */
TriangleMesh ReadSurfaceMesh(const std::string& path, double metres_per_unit = 1.0);

}  // namespace hapticsim
