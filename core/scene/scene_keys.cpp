// The table of scene keys (declared in scene.hpp): how each one is read from text, checked alone
// and written back. The relations between keys are ValidateScene's (scene.cpp).
#include <charconv>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/scene/scene.hpp"

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

// A key holding text, written as a TOML string: the outer quotes are taken off when reading and
// put back, with `"` and `\` escaped, when writing.
template <typename Ref>
KeyAccess Text(SceneKeyInfo info, Ref ref) {
  return KeyAccess{info,
                   [ref](const Scene& scene) {
                     std::string text(1, '"');
                     for (char c : ref(const_cast<Scene&>(scene))) {
                       if (c == '"' || c == '\\') text += '\\';
                       text += c;
                     }
                     text += '"';
                     return text;
                   },
                   [info, ref](Scene* scene, std::string_view text) {
                     std::string_view bare = text;
                     if (bare.size() >= 2 && bare.front() == '"' && bare.back() == '"') {
                       bare = bare.substr(1, bare.size() - 2);
                     }
                     for (char c : bare) {
                       if (static_cast<unsigned char>(c) < 0x20) {
                         Reject(info.name, text, info.allowed, info.unit);
                       }
                     }
                     ref(*scene) = std::string(bare);
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

// The object: its geometry, its mesh and its material.
void AddObjectKeys(std::vector<KeyAccess>& keys) {
  keys.push_back(Text(
      {"geometry.file", "",
       "\"\" (the built-in cube) or the path of a .nii, .nii.gz, .stl or .obj file, relative to "
       "the scene file",
       "the object's shape: a labelled NIfTI volume or a closed STL/OBJ surface (\"\": the cube)"},
      [](Scene& s) -> std::string& { return s.geometry.file; }));
  keys.push_back(Real(
      {"geometry.spacing_m", "m", "finite and >= 0 (0: a NIfTI volume's own voxel edge)",
       "edge of the voxels (elements) the geometry file becomes"},
      [](Scene& s) -> double& { return s.geometry.spacing_m; }, [](double v) { return v >= 0; }));
  keys.push_back(Real(
      {"geometry.mesh_unit", "m", "finite and > 0 (0.001 for a mesh drawn in millimetres)",
       "metres per unit of an STL or OBJ file's coordinates"},
      [](Scene& s) -> double& { return s.geometry.mesh_unit_m; }, [](double v) { return v > 0; }));
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
      {"input.waveform", "", "\"press\", \"sine\" or \"stroke\"",
       "press: s(1-cos 2πft)/2 into the object; sine: s·sin 2πft; stroke: pressed s deep, then "
       "moved across the surface through a sliding contact"},
      {"press", "sine", "stroke"},
      [](const Scene& s) { return static_cast<int>(s.input.waveform); },
      [](Scene& s, int i) { s.input.waveform = static_cast<Waveform>(i); }));
  keys.push_back(ContactNodeKey());
  keys.push_back(Real(
      {"input.stroke_length", "m", "finite and >= 0",
       "how far a stroke moves the tool along the surface (input.waveform = \"stroke\")"},
      [](Scene& s) -> double& { return s.input.stroke_length_m; },
      [](double v) { return v >= 0; }));
  keys.push_back(Choice(
      {"input.stroke_direction", "",
       "\"x\", \"-x\", \"y\", \"-y\", \"z\" or \"-z\", along the contact's face",
       "the lattice axis a stroke moves along"},
      {"x", "-x", "y", "-y", "z", "-z"},
      [](const Scene& s) { return 2 * s.input.stroke_axis + (s.input.stroke_sign < 0 ? 1 : 0); },
      [](Scene& s, int i) {
        s.input.stroke_axis = i / 2;
        s.input.stroke_sign = i % 2 == 0 ? 1 : -1;
      }));
  keys.push_back(Real(
      {"input.periods", "", "finite and > 0", "trial length in input periods"},
      [](Scene& s) -> double& { return s.input.periods; }, [](double v) { return v > 0; }));
  keys.push_back(Real(
      {"solver.dt", "s", "finite and > 0", "time step of the simulation"},
      [](Scene& s) -> double& { return s.solver.dt_s; }, [](double v) { return v > 0; }));
}

// The sliding contact of a stroke, and of hapticsimd's tool with contact.model = "proxy".
void AddContactKeys(std::vector<KeyAccess>& keys) {
  keys.push_back(Choice(
      {"contact.model", "", "\"node\" or \"proxy\"",
       "hapticsimd's contact: node = the touched node follows the tool tip (the paper's); proxy = "
       "a tool that slides (a proxy on the surface, a spring and friction; a stroke always "
       "slides)"},
      {"node", "proxy"}, [](const Scene& s) { return static_cast<int>(s.contact.model); },
      [](Scene& s, int i) { s.contact.model = static_cast<ContactModel>(i); }));
  keys.push_back(Real(
      {"contact.static_friction", "", "finite and >= 0",
       "μ_s: the proxy sticks until the tangential force exceeds μ_s × the normal force"},
      [](Scene& s) -> double& { return s.contact.static_friction; },
      [](double v) { return v >= 0; }));
  keys.push_back(Real(
      {"contact.kinetic_friction", "", "finite, >= 0 and <= contact.static_friction",
       "μ_k: a sliding proxy keeps the tangential force at μ_k × the normal force"},
      [](Scene& s) -> double& { return s.contact.kinetic_friction; },
      [](double v) { return v >= 0; }));
  keys.push_back(Real(
      {"contact.stiffness", "N/m", "finite and > 0 (and within the step's limit)",
       "the spring joining the tool to the proxy on the surface"},
      [](Scene& s) -> double& { return s.contact.stiffness_n_per_m; },
      [](double v) { return v > 0; }));
  keys.push_back(Real(
      {"contact.radius", "m", "finite and >= 0 (at most 8 lattice spacings)",
       "the tool tip's radius: the spring pushes the face nodes within it (tent weights) and "
       "reads the surface there; 0: the face cell under the proxy alone (bilinear)"},
      [](Scene& s) -> double& { return s.contact.radius_m; }, [](double v) { return v >= 0; }));
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
       "coarse cells refined around each point or line support, such as the cube's corners or "
       "a held edge (singular: a coarse cell there is far too stiff; a held surface is not)"},
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
      {"adaptivity.outer_rate", "Hz", "a whole number of Hz from 1 to the primary rate 1/solver.dt",
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
    AddContactKeys(keys);
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

}  // namespace

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

}  // namespace hapticsim
