#pragma once

#include <string>

#include "core/trial/reference_trial.hpp"
#include "core/scene/scene.hpp"

namespace hapticsim::cli {

/**
 * Draws the force on the user (each component, N) and the contact depth (m) against time as a
 * self-contained SVG image: two stacked panels sharing the time axis.
 * @throws Error when the file cannot be written.
 */
void WriteForcePlot(const std::string& path, const TrialResult& result, const Scene& scene);

}  // namespace hapticsim::cli
