#include <cmath>
#include <fstream>
#include <iostream>
#include <optional>

#include <nlohmann/json.hpp>

#include "core/error.hpp"
#include "core/reference_trial.hpp"
#include "tools/hapticsim/command.hpp"
#include "tools/hapticsim/format.hpp"
#include "tools/hapticsim/scene_options.hpp"
#include "tools/hapticsim/svg_plot.hpp"

namespace hapticsim::cli {
namespace {

struct SimulateOptions {
  SceneOptions scene;
  std::string csv_path;
  std::string plot_path;
  bool allow_unstable = false;
};

void WriteCsv(const std::string& path, const TrialResult& result) {
  std::ofstream out(path);
  HAPTICSIM_THROW_UNLESS(out.good(), "cannot write the time series to " + path +
                                         ": check that the folder exists and is writable");
  out.precision(10);
  out << "t_s,contact_ux_m,contact_uy_m,contact_uz_m,force_x_N,force_y_N,force_z_N\n";
  for (const ForceSample& s : result.samples) {
    out << s.t_s << ',' << s.contact_displacement_m[0] << ',' << s.contact_displacement_m[1]
        << ',' << s.contact_displacement_m[2] << ',' << s.feedback_force_n[0] << ','
        << s.feedback_force_n[1] << ',' << s.feedback_force_n[2] << '\n';
  }
  HAPTICSIM_THROW_UNLESS(out.good(), "writing " + path + " failed (disk full?)");
}

int Run(const SimulateOptions& options) {
  const Scene scene = options.scene.Resolve();
  const CubeScene cube(scene);
  TrialOptions trial_options;
  trial_options.run_if_predicted_unstable = options.allow_unstable;
  const TrialResult result = RunReferenceTrial(cube, trial_options);

  const bool wrote_series = !options.csv_path.empty() && !result.samples.empty();
  if (wrote_series) WriteCsv(options.csv_path, result);
  if (!options.plot_path.empty() && !result.samples.empty()) {
    WriteForcePlot(options.plot_path, result, scene);
  }

  double peak_time = 0;
  for (const ForceSample& s : result.samples) {
    const double magnitude = std::hypot(s.feedback_force_n[0], s.feedback_force_n[1],
                                        s.feedback_force_n[2]);
    if (magnitude == result.peak_force_n) peak_time = s.t_s;
  }
  const double simulated_ms = result.steps * scene.solver.dt_s * 1e3;
  const double cost_us_per_ms = simulated_ms > 0 ? result.wall_time_s * 1e6 / simulated_ms : 0;

  if (options.scene.json) {
    nlohmann::json out;
    out["outcome"] = TrialOutcomeName(result.outcome);
    out["diverged"] = result.diverged();
    out["predicted_stable"] = result.stability.IsStable(scene.solver.dt_s);
    out["critical_dt_s"] = result.stability.critical_dt_s;
    out["dt_s"] = scene.solver.dt_s;
    out["duration_s"] = scene.duration_s();
    out["steps"] = result.steps;
    out["stopped_at_s"] = result.stopped_at_s;
    out["peak_force_N"] = result.peak_force_n;
    out["peak_force_time_s"] = peak_time;
    out["wall_time_s"] = result.wall_time_s;
    out["compute_us_per_simulated_ms"] = cost_us_per_ms;
    out["time_series_csv"] = wrote_series ? nlohmann::json(options.csv_path) : nlohmann::json();
    std::cout << out.dump(2) << "\n";
  } else {
    std::cout << "Reference simulation: " << scene.mesh.nodes << "³-node cube, edge "
              << Quantity(scene.mesh.edge_m, "m") << "; " << WaveformName(scene.input.waveform)
              << " of " << Quantity(scene.input.amplitude_m, "m") << " at "
              << Quantity(scene.input.frequency_hz, "Hz") << " for "
              << Duration(scene.duration_s()) << ", dt " << Duration(scene.solver.dt_s) << "\n";
    std::cout << "  stability: critical dt " << Duration(result.stability.critical_dt_s)
              << " (Lanczos on M⁻¹K), dt is "
              << (result.stability.IsStable(scene.solver.dt_s) ? "below it: stable"
                                                                : "NOT below it: unstable")
              << "\n";
    if (result.outcome == TrialOutcome::kPredictedUnstable) {
      std::cout << "  refused: predicted unstable. Lower solver.dt below "
                << Duration(result.stability.critical_dt_s)
                << ", or pass --allow-unstable to watch the run diverge.\n";
    } else {
      if (result.diverged()) {
        std::cout << "  DIVERGED at t = " << Duration(result.stopped_at_s) << " ("
                  << TrialOutcomeName(result.outcome) << "); forces after that are not shown\n";
      }
      std::cout << "  peak force on the user: " << Quantity(result.peak_force_n, "N") << " at t = "
                << Duration(peak_time) << "\n";
      std::cout << "  " << result.steps << " steps in " << Duration(result.wall_time_s)
                << " of compute (" << Quantity(cost_us_per_ms, "µs") << " per simulated ms)\n";
    }
    if (wrote_series) {
      std::cout << "  time series (t, contact displacement, force on the user): "
                << options.csv_path << "\n";
    }
    if (!options.plot_path.empty() && !result.samples.empty()) {
      std::cout << "  plot: " << options.plot_path << "\n";
    }
  }
  return result.outcome == TrialOutcome::kCompleted ? kExitOk : kExitUnstable;
}

}  // namespace

Command AddSimulateCommand(CLI::App& parent) {
  auto options = std::make_shared<SimulateOptions>();
  CLI::App* app = parent.add_subcommand(
      "simulate",
      "Run the full-resolution reference simulation of a scene and report the force on the user");
  AddSceneOptions(app, &options->scene);
  app->add_option("--out", options->csv_path,
                  "Write the time series as CSV: t_s, contact displacement (m), force on the "
                  "user (N)")
      ->type_name("FILE.csv");
  app->add_option("--plot", options->plot_path, "Draw force against time as an SVG image")
      ->type_name("FILE.svg");
  app->add_flag("--allow-unstable", options->allow_unstable,
                "Run even when dt is past the predicted stability limit (divergence is then "
                "detected and reported)");
  return {app, [options] { return Run(*options); }};
}

}  // namespace hapticsim::cli
