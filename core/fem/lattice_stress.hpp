#pragma once

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

}  // namespace hapticsim
