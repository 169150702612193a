#include "core/scene/scene.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <sstream>

#include "core/error.hpp"
#include "core/scene/label_materials.hpp"
#include "core/scene/support_regions.hpp"

namespace hapticsim {
namespace {

// On a geometry the lattice need not be k·m + 1 nodes (the hybrid mesh refines the cells past its
// end) and whether a secondary region is left is known once the object is built (RegionPartition).
void ValidateCubeAdaptivity(const Scene& scene) {
  const AdaptivitySettings& a = scene.adaptivity;
  const int intervals = scene.mesh.nodes - 1;
  if (intervals % a.secondary_lod != 0) {
    throw Error("adaptivity.secondary_lod = " + std::to_string(a.secondary_lod) +
                " does not divide the " + std::to_string(intervals) +
                " node intervals of mesh.nodes = " + std::to_string(scene.mesh.nodes) +
                ": adaptivity.secondary_lod must divide mesh.nodes - 1");
  }
  if (PrimaryBoxCoversObject(scene, a.primary_size)) {
    int largest = 0;
    while (largest + 1 < a.primary_size && !PrimaryBoxCoversObject(scene, largest + 1)) ++largest;
    throw Error("adaptivity.primary_size = " + std::to_string(a.primary_size) +
                " covers the whole object, leaving no secondary region: adaptivity.primary_size "
                "must be from 1 to " +
                std::to_string(largest) +
                " for this mesh and "
                "adaptivity.secondary_lod, or 0 to switch adaptivity off");
  }
}

void ValidateAdaptivity(const Scene& scene) {
  const AdaptivitySettings& a = scene.adaptivity;
  if (!scene.geometry.from_file()) ValidateCubeAdaptivity(scene);
  const double primary_rate = 1.0 / scene.solver.dt_s;
  if (std::abs(primary_rate - std::round(primary_rate)) > 1e-9 * primary_rate) {
    throw Error(
        "solver.dt = " + FormatReal(scene.solver.dt_s) + " s gives a primary rate of " +
        FormatReal(primary_rate) +
        " Hz: with adaptivity on, solver.dt must be 1 / (a whole number of Hz), e.g. 0.001");
  }
  for (const auto& [key, rate] : {std::pair{"adaptivity.secondary_rate", a.secondary_rate_hz},
                                  std::pair{"adaptivity.outer_rate", a.outer_rate_hz}}) {
    if (rate > std::round(primary_rate)) {
      throw Error(std::string(key) + " = " + FormatReal(rate) + " Hz is not allowed: " + key +
                  " must be at most the primary rate 1/solver.dt = " +
                  FormatReal(std::round(primary_rate)) + " Hz");
    }
  }
}

void ValidateCubeScene(const Scene& scene) {
  if (scene.input.amplitude_m >= scene.mesh.edge_m) {
    throw Error("input.amplitude = " + FormatReal(scene.input.amplitude_m) +
                " m is not allowed: input.amplitude must be below mesh.edge = " +
                FormatReal(scene.mesh.edge_m) + " m");
  }
  if (const auto& node = scene.input.contact_node) {
    const std::string problem = ContactNodeProblem(scene.mesh, *node, scene.supports.empty());
    if (!problem.empty()) {
      throw Error("input.contact_node = " + GetSceneValue(scene, "input.contact_node") + " " +
                  problem);
    }
  }
}

// What the geometry's lattice decides (the contact node, the labels) is checked where the model
// is built (SceneModel) and where the file is read; here, what the keys alone decide.
void ValidateGeometryScene(const Scene& scene) {
  if (const auto& loaded = scene.loaded_geometry; loaded && loaded->source == scene.geometry) {
    const LabelVolume& voxels = loaded->voxels;
    const double smallest =
        voxels.spacing_m * std::min({voxels.voxels[0], voxels.voxels[1], voxels.voxels[2]});
    if (scene.input.amplitude_m >= smallest) {
      throw Error("input.amplitude = " + FormatReal(scene.input.amplitude_m) +
                  " m is not allowed: it must be below the object's smallest extent, " +
                  FormatReal(smallest) + " m");
    }
  }
}

void ValidateStroke(const Scene& scene) {
  // The proxy's face cell lies within one node of the primary's centre (it follows the proxy):
  // a primary of two nodes each way keeps the cell off its interface.
  if (scene.adaptivity.enabled() && scene.adaptivity.primary_size < 2) {
    throw Error("adaptivity.primary_size = " + std::to_string(scene.adaptivity.primary_size) +
                " is too small for a sliding contact (a stroke, or contact.model = \"proxy\"): the "
                "primary region follows the proxy and must reach two nodes from it; set "
                "adaptivity.primary_size >= 2 (or 0 for the "
                "full-resolution reference)");
  }
  if (scene.contact.kinetic_friction > scene.contact.static_friction) {
    throw Error("contact.kinetic_friction = " + FormatReal(scene.contact.kinetic_friction) +
                " is above contact.static_friction = " +
                FormatReal(scene.contact.static_friction) +
                ": the kinetic friction must not exceed the static");
  }
}

}  // namespace

std::string FormatReal(double value) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  std::string text(buffer, result.ptr);
  // Keep reals recognisable as reals in TOML ("10000.0", not "10000").
  if (text.find_first_of(".eEn") == std::string::npos) text += ".0";
  return text;
}

std::string FormatTriple(const std::array<double, 3>& values) {
  // Built piecewise: g++ 12 misreports "[" + string + … under -Wrestrict (PR 105651).
  std::string text(1, '[');
  for (int i = 0; i < 3; ++i) {
    if (i > 0) text += ", ";
    text += FormatReal(values[i]);
  }
  text += ']';
  return text;
}

long Scene::num_steps() const { return std::lround(duration_s() / solver.dt_s); }

std::string_view WaveformName(Waveform waveform) {
  switch (waveform) {
    case Waveform::kPress:
      return "press";
    case Waveform::kSine:
      return "sine";
    case Waveform::kStroke:
      return "stroke";
  }
  return "unknown";
}

bool UsesProxyContact(const Scene& scene) {
  return scene.input.waveform == Waveform::kStroke || scene.contact.model == ContactModel::kProxy;
}

void ValidateScene(const Scene& scene) {
  // Each key alone: re-set it from its own value, which runs the key's range check.
  Scene copy = scene;
  for (const SceneKeyInfo& key : SceneKeys()) SetSceneValue(&copy, key.name, GetSceneValue(scene, key.name));

  if (scene.geometry.from_file()) {
    ValidateGeometryScene(scene);
  } else {
    ValidateCubeScene(scene);
  }
  ValidateLabelMaterials(scene);
  ValidateSupportRegions(scene.supports);
  // A trial must have at least one step and must finish: cap it at 10⁸ steps.
  const double steps = scene.duration_s() / scene.solver.dt_s;
  if (!(steps >= 1.0 && steps <= 1e8)) {
    throw Error("solver.dt = " + FormatReal(scene.solver.dt_s) + " s gives " +
                FormatReal(std::round(steps)) +
                " steps for the trial of input.periods / input.frequency = " +
                FormatReal(scene.duration_s()) + " s: solver.dt must give between 1 and 1e8 steps");
  }
  if (UsesProxyContact(scene)) ValidateStroke(scene);
  if (scene.adaptivity.enabled()) ValidateAdaptivity(scene);
}

std::string ContactNodeProblem(const MeshSettings& mesh, const LatticeIndex& node,
                               bool corners_held) {
  const int last = mesh.nodes - 1;
  for (int c : node) {
    if (c < 0 || c > last) {
      return "is outside the mesh: its indices must be from 0 to mesh.nodes - 1 = " +
             std::to_string(last);
    }
  }
  if (!IsSurfaceNode(mesh, node)) {
    return "is inside the object: the contact node must be on the surface (some index 0 or " +
           std::to_string(last) + ")";
  }
  if (corners_held && IsSupportNode(mesh, node)) {
    return "is a fixed back corner: the contact node must be free to move";
  }
  return "";
}

LatticeIndex CubeContactNode(const MeshSettings& mesh) {
  const int middle = (mesh.nodes - 1) / 2;
  return {middle, middle, 0};
}

std::array<LatticeIndex, 4> CubeSupportNodes(const MeshSettings& mesh) {
  const int last = mesh.nodes - 1;
  return {LatticeIndex{0, 0, last}, LatticeIndex{last, 0, last}, LatticeIndex{0, last, last},
          LatticeIndex{last, last, last}};
}

LatticeIndex ContactNode(const Scene& scene) {
  return scene.input.contact_node ? *scene.input.contact_node : CubeContactNode(scene.mesh);
}

bool IsSurfaceNode(const MeshSettings& mesh, const LatticeIndex& node) {
  for (int c : node) {
    if (c == 0 || c == mesh.nodes - 1) return true;
  }
  return false;
}

bool IsSupportNode(const MeshSettings& mesh, const LatticeIndex& node) {
  for (const LatticeIndex& support : CubeSupportNodes(mesh)) {
    if (support == node) return true;
  }
  return false;
}

std::array<double, 3> InwardNormal(const MeshSettings& mesh, const LatticeIndex& node) {
  const int last = mesh.nodes - 1;
  for (int axis : {2, 0, 1}) {
    std::array<double, 3> normal{0.0, 0.0, 0.0};
    if (node[axis] == 0) normal[axis] = 1.0;
    if (node[axis] == last) normal[axis] = -1.0;
    if (normal[axis] != 0.0) return normal;
  }
  throw Error("internal: InwardNormal of a node inside the object");
}

double PrimaryRateHz(const Scene& scene) { return 1.0 / scene.solver.dt_s; }

bool PrimaryBoxCoversObject(const Scene& scene, int primary_size) {
  const int n = scene.mesh.nodes, k = scene.adaptivity.secondary_lod;
  for (int c : ContactNode(scene)) {
    const int lo = std::max(0, c - primary_size), hi = std::min(n - 1, c + primary_size);
    // Every coarse cell [jk, (j+1)k] overlaps (lo, hi) only if the first and last do.
    if (!(lo < k && hi > (n - 1) - k)) return false;
  }
  return true;
}

}  // namespace hapticsim
