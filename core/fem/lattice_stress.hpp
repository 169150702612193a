#pragma once

#include <cstdint>
#include <vector>

#include "core/fem/material.hpp"
#include "core/fem/object_state.hpp"

namespace hapticsim {

/**
 * The von Mises stress of every fine lattice cell, Pa, at the cell's centre, from the lattice
 * displacements (ObjectState::displacement_m: 3 per point) of a linear elastic material with
 * cells of edge `spacing_m`: the trilinear field's strain at the centre, ε = sym ∇u, then
 * σ = λ tr ε I + 2μ ε. Cells in (ix, iy, iz) order, ix slowest, as the points. Inside an unrefined
 * coarse cell the lattice holds that cell's trilinear field, so each fine cell reads its part of
 * it.
 */
std::vector<double> VonMisesPerCell(const ObjectState& state, double spacing_m,
                                    const Material& material);

/**
 * The same for an object of several materials on the lattice: `cell_material` per cell in the
 * same order (ix slowest), an index into `materials`, or −1 where the object is not (stress 0).
 * @throws Error when `cell_material` is not the lattice's cells.
 */
std::vector<double> VonMisesPerCell(const ObjectState& state, double spacing_m,
                                    const std::vector<Material>& materials,
                                    const std::vector<std::int16_t>& cell_material);

}  // namespace hapticsim
