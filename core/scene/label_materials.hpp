#pragma once

#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/scene/scene.hpp"

namespace hapticsim {

/** The keys of a [[material]] table, in print order. */
const std::vector<std::string_view>& MaterialTableKeys();

/**
 * Sets `key` (MaterialTableKeys: "label", "youngs_modulus", "poisson_ratio", "density",
 * "damping") of a [[material]] table from its text, with the [material] keys' range checks.
 * @throws Error naming the key and its allowed range, or listing the keys when it is unknown.
 */
void SetMaterialTableValue(LabelMaterial* table, std::string_view key, std::string_view text);

/** Each key of the table with its value as text that SetMaterialTableValue reads back. */
std::vector<std::pair<std::string, std::string>> MaterialTableValues(const LabelMaterial& table);

/**
 * Checks the [[material]] tables together: each label once; the cube's only label is 1; with the
 * geometry loaded, a table for every label in it and a label in it for every table.
 * @throws Error naming the table ("[[material]] 2 (label 3)") or the label without one.
 */
void ValidateLabelMaterials(const Scene& scene);

/**
 * The material of each label 0…65535 as an index into `materials` (−1: none, label 0 always),
 * and those materials: the [[material]] tables' (labels of equal materials share one: there is
 * no boundary between them), or [material] for every label when there are none.
 */
struct LabelMaterialIndex {
  std::vector<Material> materials;
  std::vector<int> index_of_label;
};
LabelMaterialIndex IndexLabelMaterials(const Scene& scene);

}  // namespace hapticsim
