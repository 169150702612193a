#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "core/scene/scene.hpp"

namespace hapticsim {

/**
 * Reads a scene file (TOML, one table per section: [mesh], [material], [input], [solver]) over
 * the defaults. Keys not in the file keep their defaults.
 * @throws Error naming the file, line and key when the file is missing or malformed, a key is
 *         unknown, or a value has the wrong type or range.
 */
Scene LoadSceneFile(const std::string& path);

/** As LoadSceneFile, from text (e.g. the scene recorded in an error map); `origin` names it. */
Scene ParseSceneText(const std::string& text, const std::string& origin);

/**
 * As ParseSceneText, without reading the geometry file or checking the scene as a whole: its
 * settings as written (each value still checked alone), for comparing what two scenes say.
 */
Scene ParseSceneSettings(const std::string& text, const std::string& origin);

/**
 * Applies "section.key=value" overrides in order (the --set option).
 * @throws Error naming the key, as SetSceneValue does, or the malformed assignment.
 */
void ApplySceneOverrides(Scene* scene, const std::vector<std::string>& assignments);

/** The scene as a TOML document that LoadSceneFile() reads back to the same scene. */
std::string FormatSceneToml(const Scene& scene);

}  // namespace hapticsim
