#include <iostream>
#include <nlohmann/json.hpp>

#include "core/scene/scene_model.hpp"
#include "core/fem/static_solver.hpp"
#include "tools/hapticsim/command.hpp"
#include "tools/hapticsim/format.hpp"
#include "tools/hapticsim/scene_options.hpp"

namespace hapticsim::cli {
namespace {

int Run(const SceneOptions& options) {
  const Scene scene = options.Resolve();
  const SceneModel object(scene);
  const std::array<double, 3> normal = object.contact_normal();
  std::array<double, 3> driven{};
  for (int c = 0; c < 3; ++c) driven[c] = scene.input.amplitude_m * normal[c];
  const StaticSolution solution = SolveStatic(object.model(), driven);
  const auto& r = solution.driven_reaction;
  // Along the press: the reaction's component on the inward normal.
  const double along = r[0] * normal[0] + r[1] * normal[1] + r[2] * normal[2];
  const double stiffness = scene.input.amplitude_m > 0 ? along / scene.input.amplitude_m : 0.0;

  const HexGrid& grid = object.model().grid();
  const std::array<int, 3> at = grid.NodeIndices(object.contact_node());
  std::array<double, 3> position = grid.NodePosition(object.contact_node());
  for (int c = 0; c < 3; ++c) position[c] += object.origin_m()[c];
  if (options.json) {
    nlohmann::json out;
    out["reaction_force_N"] = {r[0], r[1], r[2]};
    out["feedback_force_N"] = {-r[0], -r[1], -r[2]};
    out["contact_displacement_m"] = driven;
    out["contact_stiffness_N_per_m"] = stiffness;
    out["contact_node"] = at;
    out["contact_position_m"] = position;  // in the geometry's own frame
    out["contact_normal"] = normal;
    out["lattice_nodes"] = {grid.nx(), grid.ny(), grid.nz()};
    out["cg_iterations"] = solution.iterations;
    out["relative_residual"] = solution.relative_residual;
    out["converged"] = solution.converged;
    std::cout << out.dump(2) << "\n";
  } else {
    std::cout << "Static contact reaction: " << ObjectDescription(scene) << ", contact pressed "
              << Quantity(scene.input.amplitude_m, "m") << " into the object along [" << normal[0]
              << ", " << normal[1] << ", " << normal[2] << "] at node ("
              << at[0] << ", " << at[1] << ", " << at[2] << "), ("
              << Quantity(position[0], "m") << ", " << Quantity(position[1], "m") << ", "
              << Quantity(position[2], "m") << ")\n"
              << "  reaction on the object (holds the displacement): [" << Quantity(r[0], "N")
              << ", " << Quantity(r[1], "N") << ", " << Quantity(r[2], "N") << "]\n"
              << "  force on the user: " << Quantity(-along, "N") << " against the press\n"
              << "  contact stiffness: " << Quantity(stiffness, "N/m") << "\n"
              << "  conjugate gradients: " << solution.iterations
              << " iterations, relative residual " << solution.relative_residual
              << (solution.converged ? "" : " (NOT converged)") << "\n";
  }
  return solution.converged ? kExitOk : kExitInternalError;
}

}  // namespace

Command AddStaticCommand(CLI::App& parent) {
  auto options = std::make_shared<SceneOptions>();
  CLI::App* app = parent.add_subcommand(
      "static", "Static reaction at the contact for the scene's input amplitude (CG solve)");
  AddSceneOptions(app, options.get());
  return {app, [options] { return Run(*options); }};
}

}  // namespace hapticsim::cli
