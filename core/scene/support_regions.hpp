#pragma once

#include <array>
#include <string>
#include <vector>

#include "core/fem/hex_grid.hpp"
#include "core/fem/material_field.hpp"
#include "core/geometry/label_volume.hpp"
#include "core/scene/scene.hpp"

namespace hapticsim {

/** "[[support]] 2 (box)": how messages name a table. */
std::string SupportTableName(const SupportRegion& support, std::size_t index);

/**
 * Checks each [[support]] table alone: a label from 1 to 65535; a box of finite corners with
 * min ≤ max on every axis; a plane of a finite point and a finite, non-zero normal.
 * @throws Error naming the table and what to fix.
 */
void ValidateSupportRegions(const std::vector<SupportRegion>& supports);

/** Where the object's lattice sits in its geometry's frame, and its labels (null: the cube). */
struct ObjectLattice {
  const HexGrid& grid;
  const MaterialField& field;
  std::array<double, 3> origin_m{};     ///< the frame's position of grid node 0
  const LabelVolume* labels = nullptr;  ///< one label per element; null: every element label 1
};

/**
 * The object's nodes the supports hold, ascending, each once.
 * @throws Error naming a table that holds no node of the object.
 */
std::vector<int> SelectSupportNodes(const std::vector<SupportRegion>& supports,
                                    const ObjectLattice& object);

}  // namespace hapticsim
