#pragma once

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "core/regions/hybrid_mesh.hpp"
#include "core/fem/object_state.hpp"
#include "core/scene/scene.hpp"

namespace hapticsim::cli {

/**
 * A run as a VTK time series that ParaView opens (File › Open the .pvd): one XML unstructured
 * grid (.vtu) per frame, the fine lattice's hexahedra at their rest positions, with
 *   point data `displacement_m` (3 components, m: Filters › Warp By Vector draws the shape),
 *   cell data  `von_mises_pa` (Pa, at each cell's centre, VonMisesPerCell) and `region` (0 the
 *              primary, 1… the secondary shells; 0 everywhere for the reference),
 * and a .pvd collection that gives each file its time, s. Written as ASCII with 17 significant
 * digits, so a reader gets back the simulation's doubles exactly. The format is small enough to
 * write here; VTK's own library would bring a large dependency to a tool that only writes it.
 */
class VtkSeries {
 public:
  /** Frames go to `dir`/`name`/frame_NNNNN.vtu, the collection to `dir`/`name`.pvd.
   *  @throws Error when the folder cannot be made. */
  VtkSeries(const std::filesystem::path& dir, const std::string& name, const Scene& scene,
            std::vector<RegionIndex> region_per_cell);
  /** @throws Error when the file cannot be written (the message names it). */
  void Write(double t_s, const ObjectState& state);
  /** Writes the .pvd naming every frame. */
  void Finish();
  std::filesystem::path collection() const { return dir_ / (name_ + ".pvd"); }
  int frames() const { return static_cast<int>(written_.size()); }

 private:
  std::filesystem::path dir_;
  std::string name_;
  Scene scene_;
  std::vector<RegionIndex> region_per_cell_;
  std::vector<std::pair<double, std::string>> written_;  // time, file relative to dir_
};

}  // namespace hapticsim::cli
