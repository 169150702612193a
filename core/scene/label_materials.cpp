#include "core/scene/label_materials.hpp"

#include <algorithm>
#include <charconv>

#include "core/error.hpp"

namespace hapticsim {
namespace {

std::string TableName(const LabelMaterial& table, std::size_t index) {
  return "[[material]] " + std::to_string(index + 1) + " (label " + std::to_string(table.label) +
         ")";
}

std::string LabelList(const std::vector<std::uint16_t>& labels) {
  std::string list;
  for (std::uint16_t label : labels) {
    if (!list.empty()) list += ", ";
    list += std::to_string(label);
  }
  return list;
}

}  // namespace

const std::vector<std::string_view>& MaterialTableKeys() {
  static const std::vector<std::string_view> keys = {"label", "youngs_modulus", "poisson_ratio",
                                                     "density", "damping"};
  return keys;
}

void SetMaterialTableValue(LabelMaterial* table, std::string_view key, std::string_view text) {
  if (key == "label") {
    long label = 0;
    const char* end = text.data() + text.size();
    const auto [ptr, ec] = std::from_chars(text.data(), end, label);
    if (ec != std::errc() || ptr != end || label < 1 || label > 65535) {
      throw Error("label = " + std::string(text) +
                  " is not allowed: a [[material]] table's label must be a whole number from 1 "
                  "to 65535 (a label of the geometry; the cube is label 1)");
    }
    table->label = static_cast<int>(label);
    return;
  }
  if (std::find(MaterialTableKeys().begin(), MaterialTableKeys().end(), key) ==
      MaterialTableKeys().end()) {
    std::string known;
    for (std::string_view k : MaterialTableKeys())
      known += (known.empty() ? "" : ", ") + std::string(k);
    throw Error("unknown [[material]] key '" + std::string(key) + "'; known keys: " + known);
  }
  // The [material] key of the same name checks the range and says what is allowed.
  Scene scratch;
  scratch.material = table->material;
  try {
    SetSceneValue(&scratch, "material." + std::string(key), text);
  } catch (const Error& error) {
    std::string message = error.what();
    const std::string prefix = "material.";
    for (auto at = message.find(prefix); at != std::string::npos; at = message.find(prefix, at)) {
      message.erase(at, prefix.size());
    }
    throw Error(message);
  }
  table->material = scratch.material;
}

std::vector<std::pair<std::string, std::string>> MaterialTableValues(const LabelMaterial& table) {
  Scene scratch;
  scratch.material = table.material;
  std::vector<std::pair<std::string, std::string>> values = {
      {"label", std::to_string(table.label)}};
  for (std::string_view key : MaterialTableKeys()) {
    if (key == "label") continue;
    values.emplace_back(key, GetSceneValue(scratch, "material." + std::string(key)));
  }
  return values;
}

void ValidateLabelMaterials(const Scene& scene) {
  const auto& tables = scene.materials;
  for (std::size_t i = 0; i < tables.size(); ++i) {
    for (const auto& [key, text] : MaterialTableValues(tables[i])) {
      LabelMaterial copy = tables[i];
      try {
        SetMaterialTableValue(&copy, key, text);
      } catch (const Error& error) {
        throw Error(TableName(tables[i], i) + ": " + error.what());
      }
    }
    for (std::size_t j = 0; j < i; ++j) {
      HAPTICSIM_THROW_UNLESS(tables[j].label != tables[i].label,
                             TableName(tables[i], i) + " names label " +
                                 std::to_string(tables[i].label) + " again, as " +
                                 TableName(tables[j], j) + " did: give each label one table");
    }
    HAPTICSIM_THROW_UNLESS(scene.geometry.from_file() || tables[i].label == 1,
                           TableName(tables[i], i) +
                               " names a label the built-in cube does not have: the cube is "
                               "label 1 (or set geometry.file)");
  }
  if (!scene.loaded_geometry || tables.empty()) return;
  const std::vector<std::uint16_t> present = LabelsPresent(scene.loaded_geometry->voxels);
  for (std::size_t i = 0; i < tables.size(); ++i) {
    HAPTICSIM_THROW_UNLESS(
        std::find(present.begin(), present.end(), tables[i].label) != present.end(),
        TableName(tables[i], i) + ": label " + std::to_string(tables[i].label) + " is not in " +
            scene.geometry.file + " at geometry.spacing_m (its labels: " + LabelList(present) +
            ")");
  }
  for (std::uint16_t label : present) {
    const bool named = std::any_of(tables.begin(), tables.end(),
                                   [&](const LabelMaterial& t) { return t.label == label; });
    HAPTICSIM_THROW_UNLESS(
        named, scene.geometry.file + " has voxels labelled " + std::to_string(label) +
                   " but no [[material]] table names label " + std::to_string(label) + ": add one");
  }
}

LabelMaterialIndex IndexLabelMaterials(const Scene& scene) {
  LabelMaterialIndex index;
  index.index_of_label.assign(65536, -1);
  if (scene.materials.empty()) {
    index.materials = {scene.material};
    std::fill(index.index_of_label.begin() + 1, index.index_of_label.end(), 0);
    return index;
  }
  // Labels of equal materials share one: the object has no boundary between them, so the
  // regions may coarsen across it (a coarse element is of one material).
  auto same = [](const Material& a, const Material& b) {
    return a.youngs_modulus_pa == b.youngs_modulus_pa && a.poisson_ratio == b.poisson_ratio &&
           a.density_kg_m3 == b.density_kg_m3 && a.damping_per_s == b.damping_per_s;
  };
  for (const LabelMaterial& table : scene.materials) {
    const auto equal = std::find_if(index.materials.begin(), index.materials.end(),
                                    [&](const Material& m) { return same(m, table.material); });
    index.index_of_label[static_cast<std::size_t>(table.label)] =
        static_cast<int>(equal - index.materials.begin());
    if (equal == index.materials.end()) index.materials.push_back(table.material);
  }
  return index;
}

}  // namespace hapticsim
