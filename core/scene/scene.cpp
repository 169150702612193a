#include "core/scene/scene.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <functional>
#include <sstream>

#include "core/error.hpp"

namespace hapticsim {
namespace {

// Reading and writing one key: a pointer-like accessor plus the range check.
struct KeyAccess {
  SceneKeyInfo info;
  std::function<std::string(const Scene&)> get;
  std::function<void(Scene*, std::string_view)> set;
};

[[noreturn]] void Reject(std::string_view key, std::string_view value, std::string_view allowed,
                         std::string_view unit) {
  std::string message = std::string(key) + " = " + std::string(value) +
                        " is not allowed: " + std::string(key) + " must be " + std::string(allowed);
  if (!unit.empty()) message += " (in " + std::string(unit) + ")";
  throw Error(message);
}

double ParseReal(std::string_view key, std::string_view text) {
  double value = 0.0;
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, value);
  if (ec != std::errc() || ptr != end || text.empty()) {
    throw Error(std::string(key) + " = '" + std::string(text) + "' is not a number");
  }
  return value;
}

long ParseInteger(std::string_view key, std::string_view text) {
  long value = 0;
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, value);
  if (ec != std::errc() || ptr != end || text.empty()) {
    throw Error(std::string(key) + " = '" + std::string(text) + "' is not a whole number");
  }
  return value;
}

// A real-valued key: `ref` selects the field, `allowed` is the range check.
template <typename Ref>
KeyAccess Real(SceneKeyInfo info, Ref ref, std::function<bool(double)> allowed) {
  return KeyAccess{info,
                   [ref](const Scene& scene) { return FormatReal(ref(const_cast<Scene&>(scene))); },
                   [info, ref, allowed](Scene* scene, std::string_view text) {
                     const double value = ParseReal(info.name, text);
                     if (!std::isfinite(value) || !allowed(value)) {
                       Reject(info.name, text, info.allowed, info.unit);
                     }
                     ref(*scene) = value;
                   }};
}

// A whole-number key in [lo, hi].
template <typename Ref>
KeyAccess Integer(SceneKeyInfo info, Ref ref, long lo, long hi) {
  return KeyAccess{
      info, [ref](const Scene& scene) { return std::to_string(ref(const_cast<Scene&>(scene))); },
      [info, ref, lo, hi](Scene* scene, std::string_view text) {
        const long value = ParseInteger(info.name, text);
        if (value < lo || value > hi) Reject(info.name, text, info.allowed, info.unit);
        ref(*scene) = static_cast<int>(value);
      }};
}

// A key with a fixed set of names, written quoted ("press"); `get` and `set` map the scene
// field to and from the name's index.
template <typename Get, typename Set>
KeyAccess Choice(SceneKeyInfo info, std::vector<std::string_view> names, Get get, Set set) {
  return KeyAccess{info,
                   [names, get](const Scene& scene) {
                     // Built piecewise: g++ 12 misreports "\"" + string + "\"" under -Wrestrict
                     // (PR 105651).
                     std::string text(1, '"');
                     text += names[static_cast<size_t>(get(scene))];
                     text += '"';
                     return text;
                   },
                   [info, names, set](Scene* scene, std::string_view text) {
                     std::string_view bare = text;
                     if (bare.size() >= 2 && bare.front() == '"' && bare.back() == '"') {
                       bare = bare.substr(1, bare.size() - 2);
                     }
                     for (size_t i = 0; i < names.size(); ++i) {
                       if (bare == names[i]) return set(*scene, static_cast<int>(i));
                     }
                     Reject(info.name, text, info.allowed, info.unit);
                   }};
}

// input.contact_node: "middle" (the paper's node) or "ix,iy,iz". Whether the node is on the
// surface of this mesh is checked by ValidateScene, which knows mesh.nodes.
KeyAccess ContactNodeKey() {
  const SceneKeyInfo info{
      "input.contact_node", "",
      "\"middle\" or \"ix,iy,iz\" (lattice indices from 0 to mesh.nodes - 1 of a surface node "
      "that is not a fixed back corner)",
      "the driven node; \"middle\" is the paper's, the middle of the front face z = 0"};
  return KeyAccess{info,
                   [](const Scene& scene) {
                     const auto& node = scene.input.contact_node;
                     std::string text = "\"";
                     text += node ? std::to_string((*node)[0]) + "," + std::to_string((*node)[1]) +
                                        "," + std::to_string((*node)[2])
                                  : std::string("middle");
                     text += '"';
                     return text;
                   },
                   [info](Scene* scene, std::string_view text) {
                     std::string_view bare = text;
                     if (bare.size() >= 2 && bare.front() == '"' && bare.back() == '"') {
                       bare = bare.substr(1, bare.size() - 2);
                     }
                     if (bare == "middle") {
                       scene->input.contact_node.reset();
                       return;
                     }
                     LatticeIndex node{};
                     const char* p = bare.data();
                     const char* end = bare.data() + bare.size();
                     for (int c = 0; c < 3; ++c) {
                       const auto [next, ec] = std::from_chars(p, end, node[c]);
                       const bool separator_ok = c < 2 ? (next < end && *next == ',') : next == end;
                       if (ec != std::errc() || !separator_ok || node[c] < 0) {
                         Reject(info.name, text, info.allowed, info.unit);
                       }
                       p = next + 1;
                     }
                     scene->input.contact_node = node;
                   }};
}

// The object: its mesh and its material.
void AddObjectKeys(std::vector<KeyAccess>& keys) {
  keys.push_back(Integer(
      {"mesh.nodes", "", "a whole number from 2 to 401", "nodes per axis of the cube"},
      [](Scene& s) -> int& { return s.mesh.nodes; }, 2, 401));
  keys.push_back(Real(
      {"mesh.edge", "m", "finite and > 0", "edge length of the cube"},
      [](Scene& s) -> double& { return s.mesh.edge_m; }, [](double v) { return v > 0; }));
  keys.push_back(Real(
      {"material.youngs_modulus", "Pa", "finite and > 0", "Young's modulus E"},
      [](Scene& s) -> double& { return s.material.youngs_modulus_pa; },
      [](double v) { return v > 0; }));
  keys.push_back(Real(
      {"material.poisson_ratio", "", "in the open interval (-1, 0.5)", "Poisson's ratio ν"},
      [](Scene& s) -> double& { return s.material.poisson_ratio; },
      [](double v) { return v > -1.0 && v < 0.5; }));
  keys.push_back(Real(
      {"material.density", "kg/m^3", "finite and > 0", "mass density ρ"},
      [](Scene& s) -> double& { return s.material.density_kg_m3; },
      [](double v) { return v > 0; }));
  keys.push_back(Real(
      {"material.damping", "1/s", "finite and >= 0", "mass-proportional damping d in C = d·M"},
      [](Scene& s) -> double& { return s.material.damping_per_s; },
      [](double v) { return v >= 0; }));
}

// The device's input and the time step.
void AddInputKeys(std::vector<KeyAccess>& keys) {
  keys.push_back(Real(
      {"input.amplitude", "m", "finite and >= 0 (and below mesh.edge)",
       "amplitude s of the contact node's motion along its face's inward normal"},
      [](Scene& s) -> double& { return s.input.amplitude_m; }, [](double v) { return v >= 0; }));
  keys.push_back(Real(
      {"input.frequency", "Hz", "finite and > 0", "input frequency f"},
      [](Scene& s) -> double& { return s.input.frequency_hz; }, [](double v) { return v > 0; }));
  keys.push_back(Choice(
      {"input.waveform", "", "\"press\" or \"sine\"",
       "press: s(1-cos 2πft)/2 into the object; sine: s·sin 2πft"},
      {"press", "sine"},
      [](const Scene& s) { return s.input.waveform == Waveform::kPress ? 0 : 1; },
      [](Scene& s, int i) { s.input.waveform = i == 0 ? Waveform::kPress : Waveform::kSine; }));
  keys.push_back(ContactNodeKey());
  keys.push_back(Real(
      {"input.periods", "", "finite and > 0", "trial length in input periods"},
      [](Scene& s) -> double& { return s.input.periods; }, [](double v) { return v > 0; }));
  keys.push_back(Real(
      {"solver.dt", "s", "finite and > 0", "time step of the simulation"},
      [](Scene& s) -> double& { return s.solver.dt_s; }, [](double v) { return v > 0; }));
}

// The asynchronous regions.
void AddAdaptivityKeys(std::vector<KeyAccess>& keys) {
  keys.push_back(Integer(
      {"adaptivity.primary_size", "", "a whole number from 0 to 1000 (0 = no adaptivity)",
       "primary region: nodes from the contact in every direction (0 = off)"},
      [](Scene& s) -> int& { return s.adaptivity.primary_size; }, 0, 1000));
  keys.push_back(Integer(
      {"adaptivity.secondary_lod", "", "a whole number from 1 to 100",
       "secondary spacing factor k (× the finest spacing)"},
      [](Scene& s) -> int& { return s.adaptivity.secondary_lod; }, 1, 100));
  keys.push_back(Real(
      {"adaptivity.secondary_rate", "Hz",
       "a whole number of Hz from 1 to the primary rate 1/solver.dt",
       "update rate of the secondary region"},
      [](Scene& s) -> double& { return s.adaptivity.secondary_rate_hz; },
      [](double v) { return v >= 1 && v == std::floor(v); }));
  keys.push_back(Integer(
      {"adaptivity.support_layers", "", "a whole number from 0 to 100",
       "coarse cells refined around each fixed node (the supports are "
       "singular: a coarse cell there is far too stiff)"},
      [](Scene& s) -> int& { return s.adaptivity.support_layers; }, 0, 100));
  keys.push_back(Integer(
      {"adaptivity.secondary_regions", "", "a whole number from 1 to 8",
       "secondary regions: nested shells around the primary, each with its "
       "own thread"},
      [](Scene& s) -> int& { return s.adaptivity.secondary_regions; }, 1, 8));
  keys.push_back(Integer(
      {"adaptivity.shell_cells", "", "a whole number from 1 to 100",
       "thickness of each secondary shell but the last, in coarse cells"},
      [](Scene& s) -> int& { return s.adaptivity.shell_cells; }, 1, 100));
  keys.push_back(Real(
      {"adaptivity.outer_rate", "Hz",
       "a whole number of Hz from 1 to the primary rate 1/solver.dt",
       "update rate of the secondary shells beyond the first"},
      [](Scene& s) -> double& { return s.adaptivity.outer_rate_hz; },
      [](double v) { return v >= 1 && v == std::floor(v); }));
  keys.push_back(Choice(
      {"adaptivity.coupling", "", "\"displacement\" or \"force\"",
       "what an inner region sends the outer one: its displacements next to "
       "the interface (displacement) or its interface forces (force); see "
       "docs/regions.md"},
      {"displacement", "force"},
      [](const Scene& s) { return s.adaptivity.displacement_coupling ? 0 : 1; },
      [](Scene& s, int i) { s.adaptivity.displacement_coupling = i == 0; }));
}

const std::vector<KeyAccess>& KeyTable() {
  static const std::vector<KeyAccess> table = [] {
    std::vector<KeyAccess> keys;
    AddObjectKeys(keys);
    AddInputKeys(keys);
    AddAdaptivityKeys(keys);
    return keys;
  }();
  return table;
}

const KeyAccess& FindKey(std::string_view key) {
  for (const KeyAccess& access : KeyTable()) {
    if (access.info.name == key) return access;
  }
  std::string known;
  for (const KeyAccess& access : KeyTable()) {
    known += (known.empty() ? "" : ", ") + std::string(access.info.name);
  }
  throw Error("unknown scene key '" + std::string(key) + "'; known keys: " + known);
}

void ValidateAdaptivity(const Scene& scene) {
  const AdaptivitySettings& a = scene.adaptivity;
  const int intervals = scene.mesh.nodes - 1;
  if (intervals % a.secondary_lod != 0) {
    throw Error("adaptivity.secondary_lod = " + std::to_string(a.secondary_lod) +
                " does not divide the " + std::to_string(intervals) +
                " node intervals of mesh.nodes = " + std::to_string(scene.mesh.nodes) +
                ": adaptivity.secondary_lod must divide mesh.nodes - 1");
  }
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

}  // namespace

std::string FormatReal(double value) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  std::string text(buffer, result.ptr);
  // Keep reals recognisable as reals in TOML ("10000.0", not "10000").
  if (text.find_first_of(".eEn") == std::string::npos) text += ".0";
  return text;
}

long Scene::num_steps() const { return std::lround(duration_s() / solver.dt_s); }

std::string_view WaveformName(Waveform waveform) {
  return waveform == Waveform::kPress ? "press" : "sine";
}

const std::vector<SceneKeyInfo>& SceneKeys() {
  static const std::vector<SceneKeyInfo> infos = [] {
    std::vector<SceneKeyInfo> out;
    for (const KeyAccess& access : KeyTable()) out.push_back(access.info);
    return out;
  }();
  return infos;
}

void SetSceneValue(Scene* scene, std::string_view key, std::string_view value_text) {
  FindKey(key).set(scene, value_text);
}

std::string GetSceneValue(const Scene& scene, std::string_view key) {
  return FindKey(key).get(scene);
}

void ValidateScene(const Scene& scene) {
  // Each key alone: re-set it from its own value, which runs the key's range check.
  Scene copy = scene;
  for (const KeyAccess& access : KeyTable()) access.set(&copy, access.get(scene));

  if (scene.input.amplitude_m >= scene.mesh.edge_m) {
    throw Error("input.amplitude = " + FormatReal(scene.input.amplitude_m) +
                " m is not allowed: input.amplitude must be below mesh.edge = " +
                FormatReal(scene.mesh.edge_m) + " m");
  }
  // A trial must have at least one step and must finish: cap it at 10⁸ steps.
  const double steps = scene.duration_s() / scene.solver.dt_s;
  if (!(steps >= 1.0 && steps <= 1e8)) {
    throw Error("solver.dt = " + FormatReal(scene.solver.dt_s) + " s gives " +
                FormatReal(std::round(steps)) +
                " steps for the trial of input.periods / input.frequency = " +
                FormatReal(scene.duration_s()) + " s: solver.dt must give between 1 and 1e8 steps");
  }
  if (const auto& node = scene.input.contact_node) {
    const std::string problem = ContactNodeProblem(scene.mesh, *node);
    if (!problem.empty()) {
      throw Error("input.contact_node = " + GetSceneValue(scene, "input.contact_node") + " " +
                  problem);
    }
  }
  if (scene.adaptivity.enabled()) ValidateAdaptivity(scene);
}

std::string ContactNodeProblem(const MeshSettings& mesh, const LatticeIndex& node) {
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
  if (IsSupportNode(mesh, node)) {
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
