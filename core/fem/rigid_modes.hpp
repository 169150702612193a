#pragma once

#include <string>
#include <vector>

#include "core/fem/hex_grid.hpp"
#include "core/fem/material_field.hpp"

namespace hapticsim {

/**
 * Why the object of `field` on `grid` could still move as a rigid body with `fixed_nodes` held
 * in all three components, or "" when the supports remove every rigid-body mode (the stiffness
 * restricted to the free degrees of freedom is then definite, so the static solve has one answer
 * and the dynamic one does not drift).
 *
 * A part is a set of elements joined through shared faces: two hexahedra that share only an edge
 * hinge about it, and only a node swivel about it. A part is held when at least three of its
 * nodes that do not lie on one line are fixed, or belong to parts already held; the test repeats
 * until nothing changes. The answer names the first part left free: its element count, where it
 * is (its centre in the grid's frame, m) and how many held nodes it has.
 */
std::string RigidBodyModeProblem(const HexGrid& grid, const MaterialField& field,
                                 const std::vector<int>& fixed_nodes);

}  // namespace hapticsim
