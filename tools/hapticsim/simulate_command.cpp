#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>

#include "core/error.hpp"
#include "core/regions/async_regions.hpp"
#include "core/regions/realtime_schedule.hpp"
#include "core/regions/region_stroke_trial.hpp"
#include "core/trial/force_error.hpp"
#include "core/trial/reference_trial.hpp"
#include "tools/hapticsim/command.hpp"
#include "tools/hapticsim/format.hpp"
#include "tools/hapticsim/scene_options.hpp"
#include "tools/hapticsim/stepping_order_option.hpp"
#include "tools/hapticsim/svg_plot.hpp"
#include "tools/hapticsim/vtk_series.hpp"

namespace hapticsim::cli {
namespace {

struct SimulateOptions {
  SceneOptions scene;
  std::string csv_path;
  std::string plot_path;
  bool allow_unstable = false;
  bool compare_reference = false;
  bool threads = false;
  SteppingOrder order = SteppingOrder::kThreads;  // the virtual-time run's: hapticsimd's
  std::string vtk_dir;
  double vtk_rate_hz = 30;
};

// Where --vtk writes, and what it wrote (the .pvd of each run).
struct VtkOutput {
  std::filesystem::path dir;
  double rate_hz = 30;
  std::vector<std::filesystem::path> written;
};

// Frames of a trial into `series` at `rate_hz` (every period when that is faster than solver.dt).
TrialFrames FramesInto(VtkSeries& series, const Scene& scene, double rate_hz) {
  TrialFrames frames;
  frames.every_periods = std::max(1L, std::lround(1.0 / (rate_hz * scene.solver.dt_s)));
  frames.observe = [&series](double t_s, const ObjectState& state) { series.Write(t_s, state); };
  return frames;
}

// The full-resolution reference, with frames into `vtk` ("reference") when asked.
TrialResult RunReference(const Scene& scene, TrialOptions options, VtkOutput* vtk) {
  std::optional<VtkSeries> series;
  const SceneModel model(scene);
  if (vtk) {
    VtkObject object = VtkObjectOf(DescribeSceneObject(scene));
    std::vector<RegionIndex> one_region(object.cell_material.size(), 0);
    series.emplace(vtk->dir, "reference", std::move(object), std::move(one_region));
    options.frames = FramesInto(*series, scene, vtk->rate_hz);
  }
  TrialResult result = RunReferenceTrial(model, options);
  if (series) {
    series->Finish();
    vtk->written.push_back(series->collection());
  }
  return result;
}

void WriteCsv(const std::string& path, const TrialResult& result) {
  std::ofstream out(path);
  HAPTICSIM_THROW_UNLESS(out.good(), "cannot write the time series to " + path +
                                         ": check that the folder exists and is writable");
  out.precision(10);
  out << "t_s,contact_ux_m,contact_uy_m,contact_uz_m,force_x_N,force_y_N,force_z_N\n";
  for (const ForceSample& s : result.samples) {
    out << s.t_s << ',' << s.contact_displacement_m[0] << ',' << s.contact_displacement_m[1] << ','
        << s.contact_displacement_m[2] << ',' << s.feedback_force_n[0] << ','
        << s.feedback_force_n[1] << ',' << s.feedback_force_n[2] << '\n';
  }
  HAPTICSIM_THROW_UNLESS(out.good(), "writing " + path + " failed (disk full?)");
}

// Per-region facts of an adaptive run, for the report.
struct RegionReport {
  std::string name;
  int nodes, elements, substeps;
  double rate_hz, critical_dt_s, cost_us_per_ms;
};

struct AdaptiveReport {
  std::vector<RegionReport> regions;
  CoupledStability coupled;  // the bare exchange's (an analysis; the daemon no longer estimates)
  EnergyAccount energy;      // the run's energy balance (AsyncRegions::Energies)
  std::vector<std::optional<DeadlineStats>> deadlines;  // per region, with --threads
  std::optional<ForceError> threaded_vs_virtual;
  std::optional<std::size_t> stroke_moves;  // a stroke: how often the primary followed the proxy
  SteppingOrder order = SteppingOrder::kThreads;  // the virtual-time run's: hapticsimd's
};

nlohmann::json DeadlineJson(const DeadlineStats& d) {
  return {{"period_s", d.period_s},
          {"cycles", d.cycles},
          {"misses", d.misses},
          {"worst_lateness_s", d.worst_lateness_s},
          {"execution_p50_s", d.execution_p50_s},
          {"execution_p99_s", d.execution_p99_s},
          {"execution_max_s", d.execution_max_s}};
}

nlohmann::json ErrorJson(const ForceError& e) {
  return {{"l2_percent", e.l2_percent},
          {"max_magnitude_percent", e.max_magnitude_percent},
          {"max_direction_deg", e.max_direction_deg},
          {"direction_threshold_fraction_of_peak", ForceError::kDirectionThreshold}};
}

// Each region's size, schedule and cost per simulated millisecond (`compute_s` over
// `simulated_s`, > 0).
void ReportRegions(const AsyncRegions& regions, const std::vector<double>& compute_s,
                   double simulated_s, AdaptiveReport* report) {
  const double simulated_ms = simulated_s * 1e3;
  const auto& p = regions.partition();
  report->deadlines.resize(static_cast<size_t>(regions.num_regions()));
  for (RegionIndex r = 0; r < regions.num_regions(); ++r) {
    report->regions.push_back({p.RegionName(r), p.num_nodes(r), p.num_elements(r),
                               regions.schedule(r).substeps, regions.schedule(r).rate_hz,
                               regions.schedule(r).alone.critical_dt_s,
                               compute_s[r] * 1e6 / simulated_ms});
  }
}

// Nothing refused: each region takes the substeps its own limit asks for and the interface
// controllers keep the exchange from adding energy (docs/regions.md). The bare exchange's
// estimate is reported as an analysis; the runaway watch ends what the controllers cannot hold.
TrialResult RunAdaptive(const Scene& scene, bool threads, AdaptiveReport* report, VtkOutput* vtk) {
  AsyncRegions regions(scene, AsyncRegions::kSubstepSafety, AsyncRegions::InterfaceControl::kOff);
  regions.SetSteppingOrder(report->order);
  report->coupled = regions.EstimateCoupledStability();
  regions.SetInterfaceControl(AsyncRegions::InterfaceControl::kPassive);
  // Frames come from the virtual-time run, the schedule the error map measures.
  std::optional<VtkSeries> series;
  TrialFrames frames;
  if (vtk) {
    series.emplace(vtk->dir, "adaptive", VtkObjectOf(DescribeSceneObject(scene)),
                   regions.partition().mesh().RegionPerLatticeCell());
    frames = FramesInto(*series, scene, vtk->rate_hz);
  }
  TrialResult result;
  if (threads) {
    const TrialResult virtual_time = regions.RunTrial(frames);
    RealTimeSchedule schedule(regions);
    result = schedule.RunTrial();
    for (int r = 0; r < regions.num_regions(); ++r) report->deadlines.push_back(schedule.stats(r));
    if (result.samples.size() == virtual_time.samples.size()) {
      report->threaded_vs_virtual = CompareForces(result.samples, virtual_time.samples);
    }
  } else {
    result = regions.RunTrial(frames);
  }
  if (series) {
    series->Finish();
    vtk->written.push_back(series->collection());
  }
  report->energy = regions.Energies();
  std::vector<double> compute_s;
  for (RegionIndex r = 0; r < regions.num_regions(); ++r)
    compute_s.push_back(regions.compute_seconds(r));
  ReportRegions(regions, compute_s, std::max<long>(result.steps, 1) * scene.solver.dt_s, report);
  return result;
}

// A stroke on the regions: the primary follows the proxy across the face (RunRegionStroke), in
// virtual time, with frames into `vtk` ("adaptive", each with the regions of its time) when
// asked. The report's regions are those it started on.
TrialResult RunAdaptiveStroke(const Scene& scene, bool threads, AdaptiveReport* report,
                              VtkOutput* vtk) {
  HAPTICSIM_THROW_UNLESS(!threads,
                         "--threads: a stroke on the regions runs in virtual time only (the "
                         "primary follows the proxy by moving the regions); drop --threads");
  AsyncRegions regions(scene, AsyncRegions::kSubstepSafety, AsyncRegions::InterfaceControl::kOff);
  regions.SetSteppingOrder(report->order);
  report->coupled = regions.EstimateCoupledStability();
  std::optional<VtkSeries> series;
  TrialFrames frames;
  std::function<void(const AsyncRegions&)> regions_now;
  if (vtk) {
    series.emplace(vtk->dir, "adaptive", VtkObjectOf(DescribeSceneObject(scene)),
                   regions.partition().mesh().RegionPerLatticeCell());
    frames = FramesInto(*series, scene, vtk->rate_hz);
    regions_now = [&series](const AsyncRegions& now) {
      series->SetRegions(now.partition().mesh().RegionPerLatticeCell());
    };
  }
  const RegionStrokeResult run = RunRegionStroke(scene, frames, regions_now, report->order);
  if (series) {
    series->Finish();
    vtk->written.push_back(series->collection());
  }
  report->energy = run.energy;
  report->stroke_moves = run.moves.size();
  ReportRegions(regions, run.compute_s,
                std::max<long>(run.stroke.trial.steps, 1) * scene.solver.dt_s, report);
  return run.stroke.trial;
}

int Run(const SimulateOptions& options) {
  const Scene scene = options.scene.Resolve();
  const bool adaptive = scene.adaptivity.enabled();
  AdaptiveReport report;
  report.order = options.order;
  TrialOptions trial_options;
  trial_options.run_if_predicted_unstable = options.allow_unstable;
  if (options.threads && !adaptive) {
    throw Error(
        "--threads runs the asynchronous regions on real threads: set "
        "adaptivity.primary_size >= 1 too");
  }
  std::optional<VtkOutput> vtk;
  if (!options.vtk_dir.empty()) vtk = VtkOutput{options.vtk_dir, options.vtk_rate_hz, {}};
  VtkOutput* frames = vtk ? &*vtk : nullptr;
  const bool stroke = scene.input.waveform == Waveform::kStroke;
  HAPTICSIM_THROW_UNLESS(stroke || scene.contact.model != ContactModel::kProxy,
                         "contact.model = \"proxy\" is hapticsimd's sliding tool; simulate drives "
                         "the node for a press or a sine: set input.waveform = \"stroke\" to "
                         "simulate the sliding tool, or contact.model = \"node\"");
  const TrialResult result = !adaptive ? RunReference(scene, trial_options, frames)
                             : stroke  ? RunAdaptiveStroke(scene, options.threads, &report, frames)
                                       : RunAdaptive(scene, options.threads, &report, frames);
  std::optional<ForceError> error;
  std::optional<TrialResult> reference;
  // The full-resolution reference: to compare against, and beside an adaptive run in --vtk.
  const bool compare = options.compare_reference && !result.samples.empty();
  if (compare || (vtk && adaptive)) {
    Scene reference_scene = scene;
    reference_scene.adaptivity.primary_size = 0;
    TrialOptions reference_options;
    reference_options.substep_to_stability = true;
    reference = RunReference(reference_scene, reference_options, adaptive ? frames : nullptr);
  }
  if (compare) {
    if (reference->outcome != TrialOutcome::kCompleted) {
      throw Error("the full-resolution reference of this scene did not complete (" +
                  std::string(TrialOutcomeName(reference->outcome)) + "); lower solver.dt below " +
                  std::to_string(reference->stability.critical_dt_s) + " s");
    }
    std::vector<ForceSample> matched(
        reference->samples.begin(),
        reference->samples.begin() +
            static_cast<long>(std::min(reference->samples.size(), result.samples.size())));
    error = CompareForces(result.samples, matched);
  }
  const bool wrote_series = !options.csv_path.empty() && !result.samples.empty();
  if (wrote_series) WriteCsv(options.csv_path, result);
  if (!options.plot_path.empty() && !result.samples.empty()) {
    WriteForcePlot(options.plot_path, result, scene);
  }

  // When the largest force of the samples shown came (the trial's own peak may fall between them).
  double peak_time = 0, largest_shown = -1;
  for (const ForceSample& s : result.samples) {
    const double magnitude =
        std::hypot(s.feedback_force_n[0], s.feedback_force_n[1], s.feedback_force_n[2]);
    if (magnitude > largest_shown) largest_shown = magnitude, peak_time = s.t_s;
  }
  const double simulated_ms = result.steps * scene.solver.dt_s * 1e3;
  const double cost_us_per_ms = simulated_ms > 0 ? result.wall_time_s * 1e6 / simulated_ms : 0;
  // Adaptive: the bare exchange stable (an analysis: the daemon no longer estimates it).
  const bool predicted_stable =
      adaptive ? report.coupled.stable : result.stability.IsStable(scene.solver.dt_s);

  if (options.scene.json) {
    nlohmann::json out;
    out["outcome"] = TrialOutcomeName(result.outcome);
    out["diverged"] = result.diverged();
    out["predicted_stable"] = predicted_stable;
    out["adaptive"] = adaptive;
    out["critical_dt_s"] = result.stability.critical_dt_s;
    out["dt_s"] = scene.solver.dt_s;
    out["duration_s"] = scene.duration_s();
    out["steps"] = result.steps;
    out["substeps"] = result.substeps;
    out["stopped_at_s"] = result.stopped_at_s;
    out["peak_force_N"] = result.peak_force_n;
    out["peak_force_time_s"] = peak_time;
    out["wall_time_s"] = result.wall_time_s;
    out["compute_us_per_simulated_ms"] = cost_us_per_ms;
    out["time_series_csv"] = wrote_series ? nlohmann::json(options.csv_path) : nlohmann::json();
    if (adaptive) {
      out["stepping_order"] = std::string(SteppingOrderName(report.order));
      out["coupled_spectral_radius"] = report.coupled.spectral_radius;
      out["common_period_s"] = report.coupled.common_period_s;
      const EnergyAccount& e = report.energy;
      out["energy_J"] = {{"stored", e.stored_j},
                         {"input_work", e.input_work_j},
                         {"damping_dissipated", e.damping_dissipated_j},
                         {"interface_created", e.interface_created_j},
                         {"interface_dissipated", e.interface_dissipated_j},
                         {"port_refused", e.port_refused_j}};
      for (size_t i = 0; i < report.regions.size(); ++i) {
        const RegionReport& r = report.regions[i];
        out["regions"].push_back({{"name", r.name},
                                  {"nodes", r.nodes},
                                  {"elements", r.elements},
                                  {"rate_Hz", r.rate_hz},
                                  {"substeps", r.substeps},
                                  {"critical_dt_s", r.critical_dt_s},
                                  {"cost_us_per_simulated_ms", r.cost_us_per_ms}});
        if (report.deadlines[i])
          out["regions"][i]["deadlines"] = DeadlineJson(*report.deadlines[i]);
      }
      if (report.threaded_vs_virtual) {
        out["threaded_vs_virtual"] = ErrorJson(*report.threaded_vs_virtual);
      }
      if (report.stroke_moves) out["primary_moves"] = *report.stroke_moves;
    }
    if (error) {
      out["error"] = ErrorJson(*error);
      out["reference_peak_force_N"] = error->reference_peak_n;
      out["reference_compute_us_per_simulated_ms"] =
          reference->wall_time_s * 1e6 / (reference->steps * scene.solver.dt_s * 1e3);
    }
    if (vtk) {
      for (const auto& pvd : vtk->written) out["vtk"].push_back(pvd.string());
    }
    std::cout << out.dump(2) << "\n";
  } else {
    std::cout << (adaptive ? "Adaptive simulation" : "Reference simulation") << ": "
              << ObjectDescription(scene) << "; " << WaveformName(scene.input.waveform) << " of "
              << Quantity(scene.input.amplitude_m, "m") << " at "
              << Quantity(scene.input.frequency_hz, "Hz") << " for " << Duration(scene.duration_s())
              << ", dt " << Duration(scene.solver.dt_s) << "\n";
    if (adaptive) {
      std::cout << "  virtual time in the "
                << (report.order == SteppingOrder::kThreads
                        ? "threads' order (hapticsimd's, and the error map's by default)"
                        : "substeps' order (not hapticsimd's: --order threads)")
                << "\n";
      for (const RegionReport& r : report.regions) {
        std::cout << "  " << r.name << " region: " << r.nodes << " nodes, " << r.elements
                  << " elements, " << Quantity(r.rate_hz, "Hz") << " × " << r.substeps
                  << " substep(s), own limit " << Duration(r.critical_dt_s) << ", "
                  << Quantity(r.cost_us_per_ms, "µs") << " per simulated ms\n";
      }
      for (size_t i = 0; i < report.deadlines.size(); ++i) {
        if (!report.deadlines[i]) continue;
        const DeadlineStats& d = *report.deadlines[i];
        std::cout << "  " << report.regions[i].name << " thread: " << d.cycles << " cycles of "
                  << Duration(d.period_s) << ", " << d.misses << " deadline misses, worst "
                  << "wake-up lateness " << Duration(d.worst_lateness_s) << ", step time p50 "
                  << Duration(d.execution_p50_s) << " / p99 " << Duration(d.execution_p99_s)
                  << " / max " << Duration(d.execution_max_s) << "\n";
      }
      if (report.threaded_vs_virtual) {
        std::cout << "  threaded run against the virtual-time run: relative L2 "
                  << Quantity(report.threaded_vs_virtual->l2_percent, "%") << "\n";
      }
      if (report.stroke_moves) {
        std::cout << "  the primary region followed the proxy " << *report.stroke_moves
                  << " time(s) (rebuilt around the node nearest it, the motion carried over; "
                     "the regions above are where it started)\n";
      }
      const EnergyAccount& e = report.energy;
      std::cout << "  coupled stability of the bare exchange: spectral radius "
                << Quantity(report.coupled.spectral_radius, "") << "per common period of "
                << Duration(report.coupled.common_period_s) << ": "
                << (report.coupled.stable ? "stable"
                                          : "UNSTABLE bare (the interface controllers hold it "
                                            "as run; the runaway watch ends what they cannot)")
                << "\n  energy: the exchange between the regions created "
                << Quantity(e.interface_created_j, "J") << " and the interface controllers took "
                << "out " << Quantity(e.interface_dissipated_j, "J") << "; the port limits kept "
                << Quantity(e.port_refused_j, "J") << " of work out (the input did "
                << Quantity(e.input_work_j, "J") << " of work)\n";
    } else {
      std::cout << "  stability: critical dt " << Duration(result.stability.critical_dt_s)
                << " (Lanczos on M⁻¹K), dt is "
                << (predicted_stable ? "below it: stable" : "NOT below it: unstable") << "\n";
    }
    if (result.outcome == TrialOutcome::kPredictedUnstable) {
      std::cout << "  refused: predicted unstable. "
                << "Lower solver.dt below " + Duration(result.stability.critical_dt_s)
                << (scene.input.waveform == Waveform::kStroke
                        ? " (the limit with the contact spring: or lower contact.stiffness).\n"
                        : ", or pass --allow-unstable to watch the run diverge.\n");
    } else {
      if (result.outcome == TrialOutcome::kLeftSurface) {
        std::cout << "  STOPPED at t = " << Duration(result.stopped_at_s)
                  << ": the stroke reached the edge of the face it slides on; shorten "
                     "input.stroke_length or start it elsewhere (input.contact_node)\n";
      }
      if (result.diverged()) {
        std::cout << "  DIVERGED at t = " << Duration(result.stopped_at_s) << " ("
                  << (result.runaway ? "the runaway watch: the state outgrew what the energy "
                                       "balance allows; hapticsimd takes these regions to equal "
                                       "rates"
                                     : TrialOutcomeName(result.outcome))
                  << "); forces after that are not shown\n";
      }
      std::cout << "  peak force on the user: " << Quantity(result.peak_force_n, "N")
                << " at t = " << Duration(peak_time) << "\n";
      std::cout << "  " << result.steps << " steps in " << Duration(result.wall_time_s)
                << " of compute (" << Quantity(cost_us_per_ms, "µs") << " per simulated ms)\n";
    }
    if (error) {
      std::cout << "  error against the full-resolution reference (peak "
                << Quantity(error->reference_peak_n, "N") << "): relative L2 "
                << Quantity(error->l2_percent, "%") << ", worst magnitude "
                << Quantity(error->max_magnitude_percent, "%") << " of peak, worst direction "
                << Quantity(error->max_direction_deg, "°") << "\n";
    }
    if (wrote_series) {
      std::cout << "  time series (t, contact displacement, force on the user): "
                << options.csv_path << "\n";
    }
    if (!options.plot_path.empty() && !result.samples.empty()) {
      std::cout << "  plot: " << options.plot_path << "\n";
    }
    if (vtk) {
      for (const auto& pvd : vtk->written) {
        std::cout << "  VTK time series (open in ParaView; Warp By Vector on displacement_m): "
                  << pvd.string() << "\n";
      }
    }
  }
  return result.outcome == TrialOutcome::kCompleted ? kExitOk : kExitUnstable;
}

}  // namespace

Command AddSimulateCommand(CLI::App& parent) {
  auto options = std::make_shared<SimulateOptions>();
  CLI::App* app = parent.add_subcommand(
      "simulate",
      "Simulate a scene and report the force on the user: the full-resolution reference, or the "
      "asynchronous regions when adaptivity.primary_size >= 1");
  AddSceneOptions(app, &options->scene);
  app->add_option("--out", options->csv_path,
                  "Write the time series as CSV: t_s, contact displacement (m), force on the "
                  "user (N)")
      ->type_name("FILE.csv");
  app->add_option("--plot", options->plot_path, "Draw force against time as an SVG image")
      ->type_name("FILE.svg");
  app->add_flag("--allow-unstable", options->allow_unstable,
                "Run the full-resolution reference even when solver.dt is past its stability "
                "limit (divergence is then detected and reported); the adaptive regions take "
                "the substeps their own limits ask for and are never refused");
  app->add_flag("--compare-reference", options->compare_reference,
                "Also run the full-resolution reference and report the force error against it");
  app->add_flag("--threads", options->threads,
                "Run the asynchronous regions on real threads (one per region, on real clocks) "
                "and report deadlines and the difference from the virtual-time run (in --order)");
  AddSteppingOrderOption(
      app, &options->order,
      "How the virtual-time run steps the regions: 'threads' (hapticsimd's, and the error map's "
      "by default: each region's period of substeps at one wake, released ahead as its threads "
      "are; the force the daemon renders) or 'substeps' (the secondaries step before each "
      "primary substep: where a secondary runs at another rate in several substeps, an exchange "
      "the daemon does not run)");
  app->add_option("--vtk", options->vtk_dir,
                  "Write the run as a VTK time series ParaView opens: DIR/adaptive.pvd and "
                  "DIR/reference.pvd (an adaptive scene writes both), one .vtu per frame of the "
                  "object's voxels with displacement (m), von Mises stress (Pa), region id and "
                  "material")
      ->type_name("DIR");
  app->add_option("--vtk-rate", options->vtk_rate_hz, "Frames per simulated second of --vtk, Hz")
      ->capture_default_str()
      ->check(CLI::Range(0.1, 1000.0));
  return {app, [options] { return Run(*options); }};
}

}  // namespace hapticsim::cli
