#include "core/scene/scene_toml.hpp"

#include <toml++/toml.h>

#include <charconv>
#include <optional>
#include <sstream>

#include "core/error.hpp"

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

}  // namespace

// Reads `text` when given, else the file at `path` (which names the source in messages).
Scene ParseScene(const std::string& path, const std::optional<std::string>& text);

Scene LoadSceneFile(const std::string& path) { return ParseScene(path, std::nullopt); }

Scene ParseSceneText(const std::string& text, const std::string& origin) {
  return ParseScene(origin, text);
}

Scene ParseScene(const std::string& path, const std::optional<std::string>& text) {
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
    const auto* table = section_node.as_table();
    if (table == nullptr) {
      throw Error("scene file " + Location(path, section_node.source()) + ": '" + section +
                  "' must be a section like [" + section + "], with keys below it");
    }
    for (const auto& [key, node] : *table) {
      const std::string name = section + "." + std::string(key.str());
      const std::string where = "scene file " + Location(path, node.source());
      try {
        SetSceneValue(&scene, name, ValueText(node, name, where));
      } catch (const Error& error) {
        const std::string message = error.what();
        if (message.rfind("scene file", 0) == 0) throw;
        throw Error(where + ": " + message);
      }
    }
  }
  try {
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
  ValidateScene(*scene);
}

std::string FormatSceneToml(const Scene& scene) {
  std::ostringstream out;
  std::string current_section;
  for (const SceneKeyInfo& key : SceneKeys()) {
    const std::string name(key.name);
    const auto dot = name.find('.');
    const std::string section = name.substr(0, dot);
    if (section != current_section) {
      out << (current_section.empty() ? "" : "\n") << "[" << section << "]\n";
      current_section = section;
    }
    out << name.substr(dot + 1) << " = " << GetSceneValue(scene, name) << "  # " << key.meaning;
    if (!key.unit.empty()) out << ", " << key.unit;
    out << "\n";
  }
  return out.str();
}

}  // namespace hapticsim
