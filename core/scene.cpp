#include "core/scene.hpp"

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

std::string FormatReal(double value) {
  std::ostringstream out;
  out.precision(17);
  out << value;
  std::string text = out.str();
  // Keep reals recognisable as reals in TOML ("10000.0", not "10000").
  if (text.find_first_of(".eEn") == std::string::npos) text += ".0";
  return text;
}

[[noreturn]] void Reject(std::string_view key, std::string_view value, std::string_view allowed,
                         std::string_view unit) {
  std::string message = std::string(key) + " = " + std::string(value) + " is not allowed: " +
                        std::string(key) + " must be " + std::string(allowed);
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
  return KeyAccess{
      info,
      [ref](const Scene& scene) { return FormatReal(ref(const_cast<Scene&>(scene))); },
      [info, ref, allowed](Scene* scene, std::string_view text) {
        const double value = ParseReal(info.name, text);
        if (!std::isfinite(value) || !allowed(value)) {
          Reject(info.name, text, info.allowed, info.unit);
        }
        ref(*scene) = value;
      }};
}

const std::vector<KeyAccess>& KeyTable() {
  static const std::vector<KeyAccess> table = [] {
    std::vector<KeyAccess> keys;
    keys.push_back(KeyAccess{
        {"mesh.nodes", "", "a whole number from 2 to 401", "nodes per axis of the cube"},
        [](const Scene& s) { return std::to_string(s.mesh.nodes); },
        [](Scene* s, std::string_view text) {
          const long value = ParseInteger("mesh.nodes", text);
          if (value < 2 || value > 401) {
            Reject("mesh.nodes", text, "a whole number from 2 to 401", "");
          }
          s->mesh.nodes = static_cast<int>(value);
        }});
    keys.push_back(Real({"mesh.edge", "m", "finite and > 0", "edge length of the cube"},
                        [](Scene& s) -> double& { return s.mesh.edge_m; },
                        [](double v) { return v > 0; }));
    keys.push_back(Real({"material.youngs_modulus", "Pa", "finite and > 0", "Young's modulus E"},
                        [](Scene& s) -> double& { return s.material.youngs_modulus_pa; },
                        [](double v) { return v > 0; }));
    keys.push_back(Real({"material.poisson_ratio", "", "in the open interval (-1, 0.5)",
                         "Poisson's ratio ν"},
                        [](Scene& s) -> double& { return s.material.poisson_ratio; },
                        [](double v) { return v > -1.0 && v < 0.5; }));
    keys.push_back(Real({"material.density", "kg/m^3", "finite and > 0", "mass density ρ"},
                        [](Scene& s) -> double& { return s.material.density_kg_m3; },
                        [](double v) { return v > 0; }));
    keys.push_back(Real({"material.damping", "1/s", "finite and >= 0",
                         "mass-proportional damping d in C = d·M"},
                        [](Scene& s) -> double& { return s.material.damping_per_s; },
                        [](double v) { return v >= 0; }));
    keys.push_back(Real({"input.amplitude", "m", "finite and >= 0 (and below mesh.edge)",
                         "amplitude s of the contact node's motion along +z"},
                        [](Scene& s) -> double& { return s.input.amplitude_m; },
                        [](double v) { return v >= 0; }));
    keys.push_back(Real({"input.frequency", "Hz", "finite and > 0", "input frequency f"},
                        [](Scene& s) -> double& { return s.input.frequency_hz; },
                        [](double v) { return v > 0; }));
    keys.push_back(KeyAccess{
        {"input.waveform", "", "\"press\" or \"sine\"",
         "press: s(1-cos 2πft)/2 into the object; sine: s·sin 2πft"},
        [](const Scene& s) { return "\"" + std::string(WaveformName(s.input.waveform)) + "\""; },
        [](Scene* s, std::string_view text) {
          std::string_view bare = text;
          if (bare.size() >= 2 && bare.front() == '"' && bare.back() == '"') {
            bare = bare.substr(1, bare.size() - 2);
          }
          if (bare == "press") {
            s->input.waveform = Waveform::kPress;
          } else if (bare == "sine") {
            s->input.waveform = Waveform::kSine;
          } else {
            Reject("input.waveform", text, "\"press\" or \"sine\"", "");
          }
        }});
    keys.push_back(Real({"input.periods", "", "finite and > 0", "trial length in input periods"},
                        [](Scene& s) -> double& { return s.input.periods; },
                        [](double v) { return v > 0; }));
    keys.push_back(Real({"solver.dt", "s", "finite and > 0", "time step of the simulation"},
                        [](Scene& s) -> double& { return s.solver.dt_s; },
                        [](double v) { return v > 0; }));
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
                FormatReal(scene.duration_s()) +
                " s: solver.dt must give between 1 and 1e8 steps");
  }
}

}  // namespace hapticsim
