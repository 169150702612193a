#pragma once

#include <array>
#include <vector>

namespace hapticsim {

/** A triangulated surface: vertex positions (m) and triangles as three vertex indices. */
struct TriangleMesh {
  std::vector<std::array<double, 3>> vertices;
  std::vector<std::array<int, 3>> triangles;
};

/**
 * Checks that the mesh bounds a volume: every vertex finite, every index in range, no triangle
 * with two corners at one position, and every edge (vertices joined by exact position, -0 = +0)
 * shared by exactly two triangles.
 *
 * Not required: consistent orientation (the voxeliser counts crossings' parity, which does not
 * see it), and non-zero area for a triangle of three distinct but collinear corners (such a
 * sliver, left where an exporter closed a T-junction, keeps every edge count right and is
 * never crossed). A triangle with a repeated corner is refused rather than skipped: a mesh
 * built in code should not have one, and ReadSurfaceMesh already drops those it reads.
 * @throws Error saying how many edges are open (or shared by more than two triangles) and where
 *         the first one is, in metres, so the user can find it in their modeller; or which
 *         vertex, index or triangle is wrong.
 */
void CheckClosed(const TriangleMesh& mesh);

}  // namespace hapticsim
