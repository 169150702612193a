#include "core/fem/material_field.hpp"

#include <array>
#include <cmath>
#include <string>

#include "core/error.hpp"

namespace hapticsim {

MaterialField::MaterialField(const HexGrid& grid, const Material& material)
    : MaterialField(grid, std::vector<Material>{material},
                    std::vector<std::int16_t>(static_cast<size_t>(grid.num_elements()), 0)) {}

MaterialField::MaterialField(const HexGrid& grid, std::vector<Material> materials,
                             std::vector<std::int16_t> element_material)
    : ex_count_(grid.nx() - 1),
      ey_count_(grid.ny() - 1),
      ez_count_(grid.nz() - 1),
      materials_(std::move(materials)),
      element_material_(std::move(element_material)) {
  HAPTICSIM_THROW_UNLESS(static_cast<int>(element_material_.size()) == grid.num_elements(),
                         "the material field has " + std::to_string(element_material_.size()) +
                             " elements; the grid has " + std::to_string(grid.num_elements()));
  num_occupied_ = ValidateAndCountOccupied();
}

int MaterialField::ValidateAndCountOccupied() const {
  for (size_t m = 0; m < materials_.size(); ++m) {
    const Material& material = materials_[m];
    const std::string which = "material " + std::to_string(m) + ": ";
    HAPTICSIM_THROW_UNLESS(
        std::isfinite(material.youngs_modulus_pa) && material.youngs_modulus_pa > 0,
        which + "Young's modulus must be a positive number of Pa");
    HAPTICSIM_THROW_UNLESS(std::isfinite(material.poisson_ratio) && material.poisson_ratio > -1 &&
                               material.poisson_ratio < 0.5,
                           which + "Poisson's ratio must be in (-1, 0.5)");
    HAPTICSIM_THROW_UNLESS(std::isfinite(material.density_kg_m3) && material.density_kg_m3 > 0,
                           which + "density must be a positive number of kg/m^3");
    HAPTICSIM_THROW_UNLESS(std::isfinite(material.damping_per_s) && material.damping_per_s >= 0,
                           which + "damping must be a non-negative number of 1/s");
  }
  int occupied = 0;
  for (size_t e = 0; e < element_material_.size(); ++e) {
    const std::int16_t m = element_material_[e];
    HAPTICSIM_THROW_UNLESS(m == kEmpty || (m >= 0 && m < static_cast<int>(materials_.size())),
                           "element " + std::to_string(e) + " names material " + std::to_string(m) +
                               "; there are " + std::to_string(materials_.size()));
    occupied += m != kEmpty;
  }
  HAPTICSIM_THROW_UNLESS(occupied > 0, "the material field fills no element");
  return occupied;
}

int MaterialField::uniform_material() const {
  const std::int16_t first = element_material_.front();
  for (std::int16_t m : element_material_) {
    if (m != first) return -1;
  }
  return first;  // kEmpty never: a field fills at least one element
}

std::vector<bool> MaterialField::UsedMaterials() const {
  std::vector<bool> used(materials_.size(), false);
  for (std::int16_t m : element_material_) {
    if (m != kEmpty) used[static_cast<size_t>(m)] = true;
  }
  return used;
}

void MaterialField::CheckFits(const HexGrid& grid) const {
  HAPTICSIM_THROW_UNLESS(
      grid.nx() - 1 == ex_count_ && grid.ny() - 1 == ey_count_ && grid.nz() - 1 == ez_count_,
      "the material field was made for " + std::to_string(ex_count_) + " × " +
          std::to_string(ey_count_) + " × " + std::to_string(ez_count_) +
          " elements; the grid has " + std::to_string(grid.nx() - 1) + " × " +
          std::to_string(grid.ny() - 1) + " × " + std::to_string(grid.nz() - 1));
}

std::vector<bool> MaterialField::ActiveNodes(const HexGrid& grid) const {
  std::vector<bool> active(static_cast<size_t>(grid.num_nodes()), false);
  ForEachOccupied(grid, [&](const std::array<int, 8>& nodes, int) {
    for (int node : nodes) active[static_cast<size_t>(node)] = true;
  });
  return active;
}

}  // namespace hapticsim
