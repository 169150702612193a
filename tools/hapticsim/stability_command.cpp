#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>

#include "core/regions/async_regions.hpp"
#include "core/scene/scene_model.hpp"
#include "core/error.hpp"
#include "core/fem/stability_estimate.hpp"
#include "tools/hapticsim/command.hpp"
#include "tools/hapticsim/format.hpp"
#include "tools/hapticsim/scene_options.hpp"

namespace hapticsim::cli {
namespace {

// Each region's own limit and its substeps: what the coupling's stability rests on (the interface
// controllers take out what the exchange creates; docs/regions.md). With `estimate`, the coupled
// spectral radius too — an analysis, minutes for a stiff scene: of the bare exchange (what the
// daemon still verifies before it switches) and as run, with the controllers.
int RunAdaptive(const SceneOptions& options, const Scene& scene, bool estimate) {
  AsyncRegions regions(scene, AsyncRegions::kSubstepSafety, AsyncRegions::InterfaceControl::kOff);
  std::optional<CoupledStability> coupled, controlled;
  if (estimate) {
    coupled = regions.EstimateCoupledStability();
    regions.SetInterfaceControl(AsyncRegions::InterfaceControl::kPassive);
    controlled = regions.EstimateCoupledStability();
  }
  const auto& p = regions.partition();
  if (options.json) {
    nlohmann::json out;
    out["dt_s"] = scene.solver.dt_s;
    out["coupled_estimated"] = estimate;
    out["critical_dt_s"] = regions.schedule(kPrimaryRegion).alone.critical_dt_s;
    if (coupled) {  // the coupled verdict only when estimated (each region alone always is)
      out["stable"] = coupled->stable;
      out["coupled_spectral_radius"] = coupled->spectral_radius;
      out["controlled_spectral_radius"] = controlled->spectral_radius;
      out["common_period_s"] = coupled->common_period_s;
      out["power_iteration_periods"] = coupled->periods;
      out["power_iteration_norm"] = coupled->orbit_norm ? "orbit" : "euclidean";
    }
    for (RegionIndex r = 0; r < regions.num_regions(); ++r) {
      const RegionSchedule& s = regions.schedule(r);
      out["regions"].push_back({{"name", p.RegionName(r)},
                                {"nodes", p.num_nodes(r)},
                                {"elements", p.num_elements(r)},
                                {"rate_Hz", s.rate_hz},
                                {"substeps", s.substeps},
                                {"critical_dt_s", s.alone.critical_dt_s},
                                {"step_s", 1.0 / (s.rate_hz * s.substeps)}});
    }
    std::cout << out.dump(2) << "\n";
    return kExitOk;
  }
  std::cout << "Stability of the asynchronous regions: " << ObjectDescription(scene) << "\n";
  for (RegionIndex r = 0; r < regions.num_regions(); ++r) {
    const RegionSchedule& s = regions.schedule(r);
    std::cout << "  " << p.RegionName(r) << ": own limit " << Duration(s.alone.critical_dt_s)
              << " (boundary held), " << Quantity(s.rate_hz, "Hz") << " × " << s.substeps
              << " substep(s) = step " << Duration(1.0 / (s.rate_hz * s.substeps))
              << ": within it\n";
  }
  if (!coupled) {
    std::cout << "  coupled: the interface controllers take out what the exchange creates "
                 "(docs/regions.md); not estimated — add --estimate for the spectral radius of "
                 "the bare exchange (an analysis: hapticsimd no longer estimates it)\n";
    return kExitOk;
  }
  std::cout << "  coupled: spectral radius of the " << Duration(coupled->common_period_s)
            << " period map " << Quantity(coupled->spectral_radius, "") << "(" << coupled->periods
            << " periods of power iteration, "
            << (coupled->orbit_norm ? "orbit norm"
                                    : "Euclidean norm: the orbit energy is indefinite")
            << "): " << (coupled->stable ? "stable" : "UNSTABLE")
            << " (bare exchange)\n"
            << "  as run, with the interface controllers: "
            << Quantity(controlled->spectral_radius, "")
            << (controlled->stable ? "(held)" : "(NOT held)") << "\n";
  return kExitOk;
}

// The paper's adaptive configurations of the scene: primary size 1–4, spacing factor 1–3,
// secondary rate 1000–600 Hz (those the mesh allows), each with its coupled verdict.
int RunAllConfigurations(const SceneOptions& options, const Scene& base) {
  nlohmann::json rows = nlohmann::json::array();
  int stable_count = 0, total = 0;
  if (!options.json) {
    std::cout << "Coupled stability of the adaptive configurations: " << ObjectDescription(base);
    if (base.materials.empty()) {  // else each label's own, in its [[material]] table
      std::cout << ", ν " << base.material.poisson_ratio << ", E "
                << Quantity(base.material.youngs_modulus_pa, "Pa") << ", ρ "
                << Quantity(base.material.density_kg_m3, "kg/m³") << ", d "
                << Quantity(base.material.damping_per_s, "1/s");
    }
    std::cout << "\n"
              << "  spectral radius per common period (< 1 decays); rows k, r; columns rate\n"
              << "  k r     1000 Hz     900 Hz     800 Hz     700 Hz     600 Hz\n";
  }
  for (int k : {1, 2, 3}) {
    for (int r : {1, 2, 3, 4}) {
      if (!options.json) std::cout << "  " << k << " " << r << " ";
      for (double rate : {1000.0, 900.0, 800.0, 700.0, 600.0}) {
        Scene scene = base;
        scene.adaptivity.primary_size = r;
        scene.adaptivity.secondary_lod = k;
        scene.adaptivity.secondary_rate_hz = rate;
        // A configuration the object does not allow (on a geometry: a primary box that leaves no
        // secondary region, known once the regions are built) is n/a.
        std::optional<AsyncRegions> regions;
        try {
          ValidateScene(scene);
          regions.emplace(scene, AsyncRegions::kSubstepSafety,
                          AsyncRegions::InterfaceControl::kOff);
        } catch (const Error&) {
          if (!options.json) std::cout << "        n/a";
          continue;
        }
        const CoupledStability coupled = regions->EstimateCoupledStability();
        ++total;
        stable_count += coupled.stable ? 1 : 0;
        rows.push_back({{"primary_size", r},
                        {"secondary_lod", k},
                        {"secondary_rate", rate},
                        {"coupled_spectral_radius", coupled.spectral_radius},
                        {"stable", coupled.stable}});
        if (!options.json) {
          char cell[32];
          std::snprintf(cell, sizeof cell, " %9.5f%s", coupled.spectral_radius,
                        coupled.stable ? " " : "!");
          std::cout << cell << std::flush;
        }
      }
      if (!options.json) std::cout << "\n";
    }
  }
  if (options.json) {
    std::cout << nlohmann::json{{"configurations", rows},
                                {"stable", stable_count},
                                {"total", total}}
                     .dump(2)
              << "\n";
  } else {
    std::cout << "  " << stable_count << " of " << total
              << " configurations stable; ! marks the ones refused\n";
  }
  return kExitOk;
}

int Run(const SceneOptions& options, bool all_configurations, bool estimate_coupled) {
  const Scene scene = options.Resolve();
  if (all_configurations) return RunAllConfigurations(options, scene);
  if (scene.adaptivity.enabled()) return RunAdaptive(options, scene, estimate_coupled);
  const SceneModel cube(scene);
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
    std::cout << "Stability of central difference: " << ObjectDescription(scene) << "\n"
              << "  critical dt (2/ω_max, Lanczos on M⁻¹K): " << Duration(estimate.critical_dt_s)
              << "  (ω_max " << Quantity(estimate.omega_max_rad_s, "rad/s") << ", "
              << estimate.iterations << " iterations"
              << (estimate.converged ? "" : ", NOT converged") << ")\n"
              << "  element-level bound (never above the limit): "
              << Duration(estimate.element_bound_dt_s) << "\n"
              << "  dt = " << Duration(dt) << " is "
              << Quantity(100 * dt / estimate.critical_dt_s, "%")
              << " of the critical step: " << (stable ? "stable" : "UNSTABLE") << "\n";
  }
  return kExitOk;
}

}  // namespace

Command AddStabilityCommand(CLI::App& parent) {
  auto options = std::make_shared<SceneOptions>();
  auto all_configurations = std::make_shared<bool>(false);
  auto estimate = std::make_shared<bool>(false);
  CLI::App* app = parent.add_subcommand(
      "stability",
      "Critical time step of the scene and whether its solver.dt is below it; with adaptivity "
      "set, each region's own limit and substeps (--estimate: the coupled spectral radius too)");
  AddSceneOptions(app, options.get());
  app->add_flag("--estimate", *estimate,
                "With adaptivity set: estimate the coupled spectral radius per common period by "
                "power iteration, of the bare exchange and as run with the interface controllers "
                "(an analysis: hapticsimd no longer estimates it); seconds to minutes");
  app->add_flag(
      "--all-configurations", *all_configurations,
      "The bare exchange's coupled spectral radius (as --estimate) for every adaptive "
      "configuration of the paper's ranges (primary size 1-4, spacing factor 1-3, secondary rate "
      "1000-600 Hz); takes minutes");
  return {app, [options, all_configurations, estimate] {
            return Run(*options, *all_configurations, *estimate);
          }};
}

}  // namespace hapticsim::cli
