#pragma once

#include <cmath>
#include <cstdio>
#include <string>

#include "core/scene/scene.hpp"

namespace hapticsim::cli {

/** A number with 4 significant digits and its unit, e.g. Quantity(0.00293, "s") = "0.00293 s". */
inline std::string Quantity(double value, const char* unit) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.4g %s", value, unit);
  return buffer;
}

/** A duration in the most readable of s, ms, µs. */
inline std::string Duration(double seconds) {
  const double magnitude = std::abs(seconds);
  if (magnitude >= 1.0 || magnitude == 0.0) return Quantity(seconds, "s");
  if (magnitude >= 1e-3) return Quantity(seconds * 1e3, "ms");
  return Quantity(seconds * 1e6, "µs");
}

/**
 * What the scene's object is, for a heading: "13³-node cube, edge 0.25 m", or for a geometry
 * file "organ.nii: 9,261 elements of 5 mm (labels 1, 2)".
 */
inline std::string ObjectDescription(const Scene& scene) {
  if (!scene.geometry.from_file() || !scene.loaded_geometry) {
    return std::to_string(scene.mesh.nodes) + "³-node cube, edge " +
           Quantity(scene.mesh.edge_m, "m");
  }
  const LabelVolume& voxels = scene.loaded_geometry->voxels;
  std::size_t elements = 0;
  for (auto label : voxels.labels) elements += label != 0;
  std::string labels;
  for (auto label : LabelsPresent(voxels)) {
    labels += (labels.empty() ? "" : ", ") + std::to_string(label);
  }
  return scene.geometry.file + ": " + std::to_string(elements) + " elements of " +
         Quantity(voxels.spacing_m * 1e3, "mm") + " (label" +
         (labels.find(',') == std::string::npos ? " " : "s ") + labels + ")";
}

}  // namespace hapticsim::cli
