#include "core/scene/scene_toml.hpp"

#include <toml++/toml.h>

#include <algorithm>
#include <charconv>
#include <filesystem>
#include <optional>
#include <sstream>

#include "core/error.hpp"
#include "core/scene/label_materials.hpp"
#include "core/scene/scene_geometry.hpp"
#include "core/scene/support_regions.hpp"

namespace hapticsim {
namespace {

std::string Location(const std::string& path, const toml::source_region& where) {
  return path + ":" + std::to_string(where.begin.line) + ":" + std::to_string(where.begin.column);
}

// The TOML value as the text SetSceneValue() parses, so file and --set share one validation.
std::string ValueText(const toml::node& node, const std::string& key, const std::string& where) {
  if (const auto* v = node.as_integer()) return std::to_string(v->get());
  if (const auto* v = node.as_floating_point()) {
    char buffer[32];
    const auto result = std::to_chars(buffer, buffer + sizeof buffer, v->get());
    return std::string(buffer, result.ptr);
  }
  if (const auto* v = node.as_string()) return "\"" + v->get() + "\"";
  std::ostringstream type;
  type << node.type();
  throw Error(where + ": " + key + " must be a number or a string, not a " + type.str());
}

// Runs `set`, prefixing an Error it throws with `where` unless it names its place already.
template <typename Set>
void At(const std::string& where, Set&& set) {
  try {
    set();
  } catch (const Error& error) {
    const std::string message = error.what();
    if (message.rfind("scene file", 0) == 0) throw;
    throw Error(where + ": " + message);
  }
}

// The tables of an array of tables ([[name]]), each with where it is.
std::vector<const toml::table*> TablesOf(const toml::node& node, const std::string& name,
                                         const std::string& where) {
  const auto* array = node.as_array();
  std::vector<const toml::table*> tables;
  if (array != nullptr) {
    for (const toml::node& element : *array) tables.push_back(element.as_table());
  }
  if (array == nullptr || std::find(tables.begin(), tables.end(), nullptr) != tables.end()) {
    throw Error(where + ": '" + name + "' must be tables written [[" + name + "]], one per " +
                (name == "material" ? "label" : "support"));
  }
  return tables;
}

void ReadMaterialTables(Scene* scene, const toml::node& node, const std::string& path) {
  for (const toml::table* table :
       TablesOf(node, "material", "scene file " + Location(path, node.source()))) {
    LabelMaterial material;
    for (const auto& [key, value] : *table) {
      const std::string where = "scene file " + Location(path, value.source());
      const std::string name(key.str());
      const toml::node& text = value;  // a structured binding: clang 14 cannot capture one
      At(where, [&] { SetMaterialTableValue(&material, name, ValueText(text, name, where)); });
    }
    scene->materials.push_back(material);
  }
}

// Three numbers, m (or a direction).
std::array<double, 3> Triple(const toml::node& node, const std::string& key,
                             const std::string& where) {
  const auto* array = node.as_array();
  std::array<double, 3> triple{};
  if (array == nullptr || array->size() != 3) {
    throw Error(where + ": " + key + " must be three numbers, e.g. " + key + " = [0.0, 0.0, 0.1]");
  }
  for (std::size_t i = 0; i < 3; ++i) {
    const std::optional<double> value = (*array)[i].value<double>();
    if (!value) throw Error(where + ": " + key + " must be three numbers");
    triple[i] = *value;
  }
  return triple;
}

SupportRegion ReadSupportTable(const toml::table& table, const std::string& path,
                               const std::string& where) {
  SupportRegion support;
  std::string keys;
  for (const auto& [key, value] : table) {
    const std::string name(key.str()), at = "scene file " + Location(path, value.source());
    keys += (keys.empty() ? "" : ", ") + name;
    if (name == "label") {
      const std::optional<std::int64_t> label = value.value<std::int64_t>();
      if (!label || *label < 1 || *label > 65535) {
        throw Error(at + ": label must be a whole number from 1 to 65535");
      }
      support.kind = SupportRegion::Kind::kLabel;
      support.label = static_cast<int>(*label);
    } else if (name == "box_min" || name == "box_max") {
      support.kind = SupportRegion::Kind::kBox;
      (name == "box_min" ? support.box_min_m : support.box_max_m) = Triple(value, name, at);
    } else if (name == "plane_point" || name == "plane_normal") {
      support.kind = SupportRegion::Kind::kPlane;
      (name == "plane_point" ? support.point_m : support.normal) = Triple(value, name, at);
    } else {
      throw Error(at + ": unknown [[support]] key '" + name +
                  "'; a support is label = N, box_min and box_max, or plane_point and "
                  "plane_normal");
    }
  }
  const bool one_kind = keys == "label" || keys == "box_max, box_min" ||
                        keys == "box_min, box_max" || keys == "plane_normal, plane_point" ||
                        keys == "plane_point, plane_normal";
  if (!one_kind) {
    throw Error(where +
                ": a [[support]] table is one of label = N; box_min and box_max; or "
                "plane_point and plane_normal; this one has " +
                (keys.empty() ? std::string("no key") : keys));
  }
  return support;
}

void ReadSupportTables(Scene* scene, const toml::node& node, const std::string& path) {
  for (const toml::table* table :
       TablesOf(node, "support", "scene file " + Location(path, node.source()))) {
    scene->supports.push_back(
        ReadSupportTable(*table, path, "scene file " + Location(path, table->source())));
  }
}

// A geometry file named relative to the scene file is found next to it, wherever it is run from.
void ResolveGeometryPath(Scene* scene, const std::string& scene_path) {
  std::filesystem::path file(scene->geometry.file);
  if (file.empty() || file.is_absolute()) return;
  file = std::filesystem::absolute(std::filesystem::path(scene_path).parent_path() / file);
  scene->geometry.file = file.lexically_normal().string();
}

}  // namespace

// Reads `text` when given, else the file at `path` (which names the source in messages); with
// `load`, reads the geometry file too and validates the scene.
Scene ParseScene(const std::string& path, const std::optional<std::string>& text, bool load);

Scene LoadSceneFile(const std::string& path) { return ParseScene(path, std::nullopt, true); }

Scene ParseSceneText(const std::string& text, const std::string& origin) {
  return ParseScene(origin, text, true);
}

Scene ParseSceneSettings(const std::string& text, const std::string& origin) {
  return ParseScene(origin, text, false);
}

Scene ParseScene(const std::string& path, const std::optional<std::string>& text, bool load) {
  toml::table document;
  try {
    document = text ? toml::parse(*text, path) : toml::parse_file(path);
  } catch (const toml::parse_error& error) {
    const std::string description(error.description());
    if (error.source().begin.line == 0) {
      throw Error("cannot read scene file " + path + ": " + description);
    }
    throw Error("scene file " + Location(path, error.source()) + ": " + description);
  }
  Scene scene;
  for (const auto& [section_key, section_node] : document) {
    const std::string section(section_key.str());
    if (section == "material" && section_node.is_array()) {
      ReadMaterialTables(&scene, section_node, path);
      continue;
    }
    if (section == "support") {
      ReadSupportTables(&scene, section_node, path);
      continue;
    }
    const auto* table = section_node.as_table();
    if (table == nullptr) {
      throw Error("scene file " + Location(path, section_node.source()) + ": '" + section +
                  "' must be a section like [" + section + "], with keys below it");
    }
    for (const auto& [key, node] : *table) {
      const std::string name = section + "." + std::string(key.str());
      const std::string where = "scene file " + Location(path, node.source());
      const toml::node& text = node;  // a structured binding: clang 14 cannot capture one
      At(where, [&] { SetSceneValue(&scene, name, ValueText(text, name, where)); });
    }
  }
  if (!text) ResolveGeometryPath(&scene, path);
  if (!load) return scene;
  try {
    LoadSceneGeometry(&scene);
    ValidateScene(scene);
  } catch (const Error& error) {
    throw Error("scene file " + path + ": " + error.what());
  }
  return scene;
}

void ApplySceneOverrides(Scene* scene, const std::vector<std::string>& assignments) {
  for (const std::string& assignment : assignments) {
    const auto equals = assignment.find('=');
    if (equals == std::string::npos || equals == 0) {
      throw Error("--set '" + assignment + "' must have the form section.key=value, e.g. " +
                  "--set material.poisson_ratio=0.49");
    }
    SetSceneValue(scene, assignment.substr(0, equals), assignment.substr(equals + 1));
  }
  LoadSceneGeometry(scene);
  ValidateScene(*scene);
}

namespace {

void FormatTables(const Scene& scene, std::ostringstream& out) {
  for (const LabelMaterial& material : scene.materials) {
    out << "\n[[material]]\n";
    for (const auto& [key, value] : MaterialTableValues(material)) {
      out << key << " = " << value << "\n";
    }
  }
  for (const SupportRegion& support : scene.supports) {
    out << "\n[[support]]\n";
    switch (support.kind) {
      case SupportRegion::Kind::kLabel:
        out << "label = " << support.label << "\n";
        break;
      case SupportRegion::Kind::kBox:
        out << "box_min = " << FormatTriple(support.box_min_m) << "  # m\n"
            << "box_max = " << FormatTriple(support.box_max_m) << "  # m\n";
        break;
      case SupportRegion::Kind::kPlane:
        out << "plane_point = " << FormatTriple(support.point_m) << "  # m\n"
            << "plane_normal = " << FormatTriple(support.normal) << "\n";
        break;
    }
  }
}

}  // namespace

std::string FormatSceneToml(const Scene& scene) {
  std::ostringstream out;
  std::string current_section;
  for (const SceneKeyInfo& key : SceneKeys()) {
    const std::string name(key.name);
    const auto dot = name.find('.');
    const std::string section = name.substr(0, dot);
    // The cube's scene is written as it always was; [[material]] tables replace [material].
    if (section == "geometry" && !scene.geometry.from_file()) continue;
    if (section == "material" && !scene.materials.empty()) continue;
    // A stroke's keys act only on a sliding contact: the press and the sine are written as they
    // were.
    const bool stroke_key = section == "contact" || name.rfind("input.stroke_", 0) == 0;
    if (stroke_key && !UsesProxyContact(scene)) continue;
    if (section != current_section) {
      out << (current_section.empty() ? "" : "\n") << "[" << section << "]\n";
      current_section = section;
    }
    out << name.substr(dot + 1) << " = " << GetSceneValue(scene, name) << "  # " << key.meaning;
    if (!key.unit.empty()) out << ", " << key.unit;
    out << "\n";
  }
  FormatTables(scene, out);
  return out.str();
}

}  // namespace hapticsim
