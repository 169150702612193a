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
 * Velocity rather than the previous displacement: central difference keeps u⁻ = u − v·h, and h
 * is each region's own substep, which differs between configurations.
 */
struct ObjectState {
  int nodes_per_axis = 0;
  std::vector<double> displacement_m;  ///< 3 per lattice point, at Index(ix, iy, iz)
  std::vector<double> velocity_m_per_s;

  /** The first of a lattice point's three components. */
  std::size_t Index(int ix, int iy, int iz) const {
    return 3 * ((static_cast<std::size_t>(ix) * nodes_per_axis + iy) * nodes_per_axis + iz);
  }
  std::array<double, 3> DisplacementAt(int ix, int iy, int iz) const {
    const std::size_t i = Index(ix, iy, iz);
    return {displacement_m[i], displacement_m[i + 1], displacement_m[i + 2]};
  }
};

}  // namespace hapticsim
