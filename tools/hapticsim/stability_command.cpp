#include <iostream>

#include <nlohmann/json.hpp>

#include "core/async_regions.hpp"
#include "core/cube_scene.hpp"
#include "core/stability_estimate.hpp"
#include "tools/hapticsim/command.hpp"
#include "tools/hapticsim/format.hpp"
#include "tools/hapticsim/scene_options.hpp"

namespace hapticsim::cli {
namespace {

int RunAdaptive(const SceneOptions& options, const Scene& scene) {
  AsyncRegions regions(scene);
  const CoupledStability coupled = regions.EstimateCoupledStability();
  const auto& p = regions.partition();
  if (options.json) {
    nlohmann::json out;
    out["dt_s"] = scene.solver.dt_s;
    out["stable"] = coupled.stable;
    out["critical_dt_s"] = regions.schedule(kPrimaryRegion).alone.critical_dt_s;
    out["coupled_spectral_radius"] = coupled.spectral_radius;
    out["common_period_s"] = coupled.common_period_s;
    out["power_iteration_periods"] = coupled.periods;
    for (RegionIndex r : {kPrimaryRegion, kSecondaryRegion}) {
      const RegionSchedule& s = regions.schedule(r);
      out["regions"].push_back({{"name", r == kPrimaryRegion ? "primary" : "secondary"},
                                {"nodes", p.num_nodes(r)},
                                {"elements", p.num_elements(r)},
                                {"rate_Hz", s.rate_hz},
                                {"substeps", s.substeps},
                                {"critical_dt_s", s.alone.critical_dt_s},
                                {"step_s", 1.0 / (s.rate_hz * s.substeps)}});
    }
    std::cout << out.dump(2) << "\n";
  } else {
    std::cout << "Stability of the asynchronous regions: " << scene.mesh.nodes << "³-node cube\n";
    for (RegionIndex r : {kPrimaryRegion, kSecondaryRegion}) {
      const RegionSchedule& s = regions.schedule(r);
      std::cout << "  " << (r == kPrimaryRegion ? "primary  " : "secondary") << ": own limit "
                << Duration(s.alone.critical_dt_s) << " (boundary held), "
                << Quantity(s.rate_hz, "Hz") << " × " << s.substeps << " substep(s) = step "
                << Duration(1.0 / (s.rate_hz * s.substeps)) << ": stable alone\n";
    }
    std::cout << "  coupled: spectral radius of the " << Duration(coupled.common_period_s)
              << " period map " << Quantity(coupled.spectral_radius, "") << "("
              << coupled.periods << " periods of power iteration): "
              << (coupled.stable ? "stable" : "UNSTABLE — this configuration is refused") << "\n";
  }
  return kExitOk;
}

int Run(const SceneOptions& options) {
  const Scene scene = options.Resolve();
  if (scene.adaptivity.enabled()) return RunAdaptive(options, scene);
  const CubeScene cube(scene);
  const StabilityEstimate estimate = EstimateStability(cube.model());
  const double dt = scene.solver.dt_s;
  const bool stable = estimate.IsStable(dt);

  if (options.json) {
    nlohmann::json out;
    out["critical_dt_s"] = estimate.critical_dt_s;
    out["dt_s"] = dt;
    out["stable"] = stable;
    out["element_bound_dt_s"] = estimate.element_bound_dt_s;
    out["omega_max_rad_s"] = estimate.omega_max_rad_s;
    out["eigen_iterations"] = estimate.iterations;
    out["eigen_converged"] = estimate.converged;
    out["dt_fraction_of_critical"] = dt / estimate.critical_dt_s;
    std::cout << out.dump(2) << "\n";
  } else {
    std::cout << "Stability of central difference: " << scene.mesh.nodes << "³-node cube\n"
              << "  critical dt (2/ω_max, Lanczos on M⁻¹K): "
              << Duration(estimate.critical_dt_s) << "  (ω_max "
              << Quantity(estimate.omega_max_rad_s, "rad/s") << ", " << estimate.iterations
              << " iterations" << (estimate.converged ? "" : ", NOT converged") << ")\n"
              << "  element-level bound (never above the limit): "
              << Duration(estimate.element_bound_dt_s) << "\n"
              << "  dt = " << Duration(dt) << " is " << Quantity(100 * dt / estimate.critical_dt_s, "%")
              << " of the critical step: " << (stable ? "stable" : "UNSTABLE") << "\n";
  }
  return kExitOk;
}

}  // namespace

Command AddStabilityCommand(CLI::App& parent) {
  auto options = std::make_shared<SceneOptions>();
  CLI::App* app = parent.add_subcommand(
      "stability", "Critical time step of the scene and whether its solver.dt is below it");
  AddSceneOptions(app, options.get());
  return {app, [options] { return Run(*options); }};
}

}  // namespace hapticsim::cli
