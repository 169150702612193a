#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "core/fem/material.hpp"
#include "core/fem/object_state.hpp"
#include "core/regions/hybrid_mesh.hpp"
#include "core/scene/scene_model.hpp"

namespace hapticsim::cli {

/** What the frames draw: the object's lattice and the material of each of its cells. */
struct VtkObject {
  std::array<int, 3> lattice_nodes{};
  double spacing_m = 0;
  std::vector<Material> materials;
  /// Per lattice cell, ix slowest (ObjectState's order): an index into materials, or −1 where
  /// the object is not.
  std::vector<std::int16_t> cell_material;
};

/** The scene's object as VtkSeries draws it. */
VtkObject VtkObjectOf(const SceneObject& object);

/**
 * A run as a VTK time series that ParaView opens (File › Open the .pvd): one XML unstructured
 * grid (.vtu) per frame, the object's voxels (the fine lattice's cells it fills: every cell of the
 * cube) as hexahedra at their rest positions, with
 *   point data `displacement_m` (3 components, m: Filters › Warp By Vector draws the shape) at
 *              every lattice point, point (ix, iy, iz) number (ix·ny + iy)·nz + iz (a point no
 *              voxel uses: zero, and no cell refers to it),
 *   cell data  `von_mises_pa` (Pa, at each cell's centre, VonMisesPerCell, of the cell's
 *              material), `region` (0 the primary, 1… the secondary shells; 0 everywhere for the
 *              reference) and `material` (0, 1, … the distinct materials in the order of the
 *              [[material]] tables that first give them; tables of equal material share one),
 * and a .pvd collection that gives each file its time, s. Written as ASCII with 17 significant
 * digits, so a reader gets back the simulation's doubles exactly. The format is small enough to
 * write here; VTK's own library would bring a large dependency to a tool that only writes it.
 */
class VtkSeries {
 public:
  /** Frames go to `dir`/`name`/frame_NNNNN.vtu, the collection to `dir`/`name`.pvd.
   *  @throws Error when the folder cannot be made. */
  VtkSeries(const std::filesystem::path& dir, const std::string& name, VtkObject object,
            std::vector<RegionIndex> region_per_cell);
  /** @throws Error when the file cannot be written (the message names it). */
  void Write(double t_s, const ObjectState& state);
  /** The regions of the frames written from now on (a stroke's primary follows its proxy). */
  void SetRegions(std::vector<RegionIndex> region_per_cell);
  /** Writes the .pvd naming every frame. */
  void Finish();
  std::filesystem::path collection() const { return dir_ / (name_ + ".pvd"); }
  int frames() const { return static_cast<int>(written_.size()); }

  /** A cell of the object: its lattice cell's number (ix slowest) and its lowest corner. */
  struct Cell {
    std::size_t lattice_cell;
    std::array<int, 3> corner;
  };

 private:
  std::filesystem::path dir_;
  std::string name_;
  VtkObject object_;
  std::vector<Cell> cells_;  // the object's cells, in the order the frames list them
  std::vector<RegionIndex> region_per_cell_;
  std::vector<std::pair<double, std::string>> written_;  // time, file relative to dir_
};

}  // namespace hapticsim::cli
