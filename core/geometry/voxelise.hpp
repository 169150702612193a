#pragma once

#include <cstdint>

#include "core/geometry/label_volume.hpp"
#include "core/geometry/surface_mesh.hpp"

namespace hapticsim {

/**
 * The voxels of edge `spacing_m` whose centres lie inside the closed surface `mesh`, labelled
 * `label`; the volume's origin is the mesh's bounding box's lowest corner, and it has
 * ceil(extent / spacing_m) voxels along each axis (at least 1). Which triangles each ray of
 * centres crosses is decided exactly (vertices snapped to 2^-24 of a voxel, see voxelise.cpp),
 * so rays that graze edges and vertices count right; the test is independent of the triangles'
 * orientation, and deterministic. A centre exactly on the surface is decided as if moved a
 * hair's breadth along +z (on a face seen edge-on from z: along +x, then +y), so a box whose
 * faces lie on planes of centres is half-open, [low, high): one layer fewer on its high sides.
 * @throws Error when the mesh is not closed (CheckClosed), the spacing is not finite and > 0,
 *         the label is 0, or the lattice would exceed kMaxSourceVoxels.
 */
LabelVolume VoxeliseClosedSurface(const TriangleMesh& mesh, double spacing_m,
                                  std::uint16_t label = 1);

}  // namespace hapticsim
