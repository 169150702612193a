#pragma once

#include <array>
#include <cstddef>
#include <vector>

namespace hapticsim {

/**
 * The whole object's motion at one moment, on the fine lattice: the displacement and velocity
 * of every lattice point, whatever resolution covered it. It is what a configuration hands the
 * next one when the regions are replaced while the object is deformed (a switch in contact):
 * independent of any region partition, so any configuration of the same object can start from it
 * (AsyncRegions::CaptureState, AsyncRegions::RestoreState).
 *
 * A lattice point outside the object (an empty voxel's corner no occupied voxel touches) holds
 * zero.
 *
 * Velocity rather than the previous displacement: central difference keeps u⁻ = u − v·h, and h
 * is each region's own substep, which differs between configurations.
 */
struct ObjectState {
  /// Lattice points along x, y and z: the cube's n, n, n, or a geometry's lattice.
  std::array<int, 3> lattice_nodes{};
  std::vector<double> displacement_m;  ///< 3 per lattice point, at Index(ix, iy, iz)
  std::vector<double> velocity_m_per_s;

  std::size_t num_points() const {
    return static_cast<std::size_t>(lattice_nodes[0]) * lattice_nodes[1] * lattice_nodes[2];
  }
  /** The first of a lattice point's three components (ix slowest, iz fastest). */
  std::size_t Index(int ix, int iy, int iz) const {
    return 3 * ((static_cast<std::size_t>(ix) * lattice_nodes[1] + iy) * lattice_nodes[2] + iz);
  }
  std::array<double, 3> DisplacementAt(int ix, int iy, int iz) const {
    const std::size_t i = Index(ix, iy, iz);
    return {displacement_m[i], displacement_m[i + 1], displacement_m[i + 2]};
  }
};

}  // namespace hapticsim
