#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/fem/hex_grid.hpp"
#include "core/fem/material.hpp"

namespace hapticsim {

/**
 * Which material fills each element of a HexGrid, or none: an object of any shape on the lattice
 * (a masked grid) and of several tissues (an inclusion stiffer than what surrounds it).
 *
 * Elements are numbered like nodes, x fastest: element(ex, ey, ez) = ex + (nx−1)·(ey + (ny−1)·ez).
 * Each holds an index into materials(), or kEmpty. A node belongs to the object when an occupied
 * element touches it; the others have no stiffness and no mass (ElasticModel holds them).
 */
class MaterialField {
 public:
  static constexpr std::int16_t kEmpty = -1;

  /** Every element of `grid` filled with `material`: the paper's cube. */
  MaterialField(const HexGrid& grid, const Material& material);
  /**
   * Elements filled as `element_material` says (kEmpty or an index into `materials`).
   * @throws Error when the sizes disagree, an index is out of range, a material is not
   *         physical (E, ρ > 0, −1 < ν < 0.5, d ≥ 0, all finite) or no element is occupied.
   */
  MaterialField(const HexGrid& grid, std::vector<Material> materials,
                std::vector<std::int16_t> element_material);

  int num_elements() const { return static_cast<int>(element_material_.size()); }
  int Element(int ex, int ey, int ez) const { return ex + ex_count_ * (ey + ey_count_ * ez); }
  /** The material index of element e, or kEmpty. */
  std::int16_t material_of(int element) const { return element_material_[element]; }
  bool occupied(int element) const { return element_material_[element] != kEmpty; }
  int num_occupied() const { return num_occupied_; }
  const std::vector<Material>& materials() const { return materials_; }
  /** One material in every element (which one, else −1): the uniform cube's operator applies. */
  int uniform_material() const;
  /** Per material: whether an element is made of it (an unused one bounds nothing). */
  std::vector<bool> UsedMaterials() const;
  /** @throws Error unless this field was made for a grid of `grid`'s node counts. */
  void CheckFits(const HexGrid& grid) const;

  /**
   * `each(nodes, material)` for every occupied element of `grid`, in element order (x fastest):
   * its 8 nodes (HexGrid::ElementNodes) and its material index.
   */
  template <typename Each>
  void ForEachOccupied(const HexGrid& grid, Each&& each) const {
    CheckFits(grid);
    for (int ez = 0; ez < ez_count_; ++ez) {
      for (int ey = 0; ey < ey_count_; ++ey) {
        for (int ex = 0; ex < ex_count_; ++ex) {
          const std::int16_t m = element_material_[static_cast<std::size_t>(Element(ex, ey, ez))];
          if (m != kEmpty) each(grid.ElementNodes(ex, ey, ez), static_cast<int>(m));
        }
      }
    }
  }

  /** Per node: whether an occupied element touches it. */
  std::vector<bool> ActiveNodes(const HexGrid& grid) const;

 private:
  /** @throws Error naming what is wrong; returns the occupied elements. */
  int ValidateAndCountOccupied() const;

  int ex_count_, ey_count_, ez_count_;
  std::vector<Material> materials_;
  std::vector<std::int16_t> element_material_;
  int num_occupied_ = 0;
};

}  // namespace hapticsim
