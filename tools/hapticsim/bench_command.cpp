// hapticsim bench: run time against error. On a scene, every adaptive configuration of the
// paper's adaptivity axes is run by the sweep's own code (the scene's material and input, the
// full-resolution reference beside it) and the cheapest configuration for each error level —
// the Pareto front — is printed beside the reference's cost. With --kernels, the matrix-free
// K·u against the assembled sparse product, timed side by side in this process.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "core/fem/assembled_stiffness.hpp"
#include "core/regions/async_regions.hpp"
#include "core/fem/cpu_dispatch.hpp"
#include "core/scene/scene_model.hpp"
#include "core/error.hpp"
#include "core/errormap/error_sweep.hpp"
#include "core/fem/hex_grid.hpp"
#include "core/errormap/pareto_front.hpp"
#include "core/trial/reference_trial.hpp"
#include "core/fem/stencil_stiffness.hpp"
#include "core/errormap/sweep_grid.hpp"
#include "daemon/supervisor.hpp"
#include "tools/hapticsim/command.hpp"
#include "tools/hapticsim/format.hpp"
#include "tools/hapticsim/progress_line.hpp"
#include "tools/hapticsim/scatter_chart.hpp"
#include "tools/hapticsim/scene_options.hpp"

namespace hapticsim::cli {
namespace {

using Json = nlohmann::json;
using Clock = std::chrono::steady_clock;

// Force errors closer than this are one level on the Pareto front (the table prints two
// decimals): twice the cost for 10⁻⁶ % less error is not a trade anyone wants.
constexpr double kErrorResolution_percent = 0.01;

struct BenchOptions {
  SceneOptions scene;
  bool kernels = false;
  std::vector<int> kernel_nodes;
  double seconds = 1.0;  // per kernel and size
  int jobs = 1;
  std::string plot;
  // A scene's configurations: the paper's adaptivity axes unless given.
  std::string primary_sizes, secondary_lods, secondary_rates;
};

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

std::vector<double> ParseNumberList(const std::string& text, const char* option) {
  std::vector<double> values;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    try {
      size_t used = 0;
      values.push_back(std::stod(item, &used));
      HAPTICSIM_THROW_UNLESS(used == item.size(), "");
    } catch (...) {
      throw Error(std::string(option) + " " + text +
                  ": expected numbers separated by commas, e.g. 13,25");
    }
  }
  HAPTICSIM_THROW_UNLESS(!values.empty(), std::string(option) + " needs at least one value");
  return values;
}

// ---- --kernels ----------------------------------------------------------------------------

struct KernelTiming {
  int nodes = 0;
  double matrix_free_us = 0, assembled_us = 0, speedup = 0, matrix_free_gflops = 0;
  int rounds = 0;
};

// Seconds per call of `apply`, over a batch of `calls`.
template <class Apply>
double SecondsPerCall(const Apply& apply, int calls) {
  const auto t0 = Clock::now();
  for (int i = 0; i < calls; ++i) apply();
  return std::chrono::duration<double>(Clock::now() - t0).count() / calls;
}

// Both products on the same u, in alternating rounds of about 20 ms each, so that whatever else
// the machine does falls on both; the speed-up is the median of the rounds' own ratios.
KernelTiming TimeKernels(int nodes, double seconds) {
  const HexGrid grid(nodes, nodes, nodes, 0.25 / (nodes - 1));
  const Material material;
  const StencilStiffness stencil(grid, material);
  const AssembledStiffness assembled(grid, material);
  const Eigen::VectorXd u = Eigen::VectorXd::LinSpaced(grid.num_dofs(), -1e-3, 1e-3);
  Eigen::VectorXd ku_stencil(grid.num_dofs()), ku_assembled(grid.num_dofs());
  auto run_stencil = [&] { stencil.Apply(u, ku_stencil); };
  auto run_assembled = [&] { assembled.Apply(u, ku_assembled); };
  // Warm up, and check both compute the same product before timing them.
  run_stencil();
  run_assembled();
  const double difference = (ku_stencil - ku_assembled).norm() / ku_assembled.norm();
  HAPTICSIM_THROW_UNLESS(difference < 1e-10, "the matrix-free and assembled products differ by " +
                                                 std::to_string(difference) + " (relative)");
  const int stencil_calls = std::max(1, static_cast<int>(0.02 / SecondsPerCall(run_stencil, 1)));
  const int assembled_calls =
      std::max(1, static_cast<int>(0.02 / SecondsPerCall(run_assembled, 1)));
  std::vector<double> s, a, ratio;
  const auto start = Clock::now();
  do {
    s.push_back(SecondsPerCall(run_stencil, stencil_calls));
    a.push_back(SecondsPerCall(run_assembled, assembled_calls));
    ratio.push_back(a.back() / s.back());
  } while (s.size() < 5 ||
           std::chrono::duration<double>(Clock::now() - start).count() < 2 * seconds);
  KernelTiming t;
  t.nodes = nodes;
  t.rounds = static_cast<int>(s.size());
  t.matrix_free_us = Median(s) * 1e6;
  t.assembled_us = Median(a) * 1e6;
  t.speedup = Median(ratio);
  t.matrix_free_gflops = stencil.FlopsPerApply() / (t.matrix_free_us * 1e-6) * 1e-9;
  return t;
}

int RunKernels(const BenchOptions& o) {
  std::vector<KernelTiming> timings;
  for (int n : o.kernel_nodes) {
    HAPTICSIM_THROW_UNLESS(n >= 3 && n <= 129,
                           "--nodes " + std::to_string(n) + ": nodes per axis must be in [3, 129]");
    if (!o.scene.json) std::cerr << "timing K·u on " << n << "³ nodes…\n";
    timings.push_back(TimeKernels(n, o.seconds));
  }
  if (o.scene.json) {
    Json kernels = Json::array();
    for (const KernelTiming& t : timings) {
      kernels.push_back({{"nodes_per_axis", t.nodes},
                         {"matrix_free_us", t.matrix_free_us},
                         {"assembled_us", t.assembled_us},
                         {"speedup", t.speedup},
                         {"matrix_free_gflops", t.matrix_free_gflops},
                         {"rounds", t.rounds}});
    }
    std::cout
        << Json{{"kernels", kernels}, {"kernel_instruction_set", KernelInstructionSet()}}.dump(2)
        << "\n";
    return kExitOk;
  }
  std::cout << "K·u, matrix-free (27-point stencil) against assembled (Eigen CSR), side by side;\n"
               "medians of alternating rounds; the kernels run with "
            << KernelInstructionSet() << "\n\n"
            << "  nodes   matrix-free    assembled   speed-up   matrix-free GFLOP/s   rounds\n";
  for (const KernelTiming& t : timings) {
    char line[160];
    std::snprintf(line, sizeof line, "  %3d³  %10.1f µs  %9.1f µs  %8.1f×  %19.1f  %7d\n", t.nodes,
                  t.matrix_free_us, t.assembled_us, t.speedup, t.matrix_free_gflops, t.rounds);
    std::cout << line;
  }
  return kExitOk;
}

// ---- a scene ------------------------------------------------------------------------------

struct ConfigurationResult {
  RegionConfiguration configuration;
  SampleStatus status = SampleStatus::kNotComputed;
  std::array<double, kMapCostRegions> cost_us_per_ms{};
  double cost_us_per_ms_total = 0;
  double primary_period_share = 0;  // the primary's compute per period / its period
  double l2_percent = 0;
  double max_magnitude_percent = 0;
  std::vector<int> substeps;  // per region
};

// The reference's cost: the stepping loop of the whole cube at full resolution (substepped where
// its stability needs it), median of three runs.
double ReferenceCostUsPerMs(const Scene& scene, int* substeps) {
  Scene full = scene;
  full.adaptivity.primary_size = 0;
  const SceneModel cube(full);
  TrialOptions options;
  options.substep_to_stability = true;
  std::vector<double> costs;
  for (int k = 0; k < 3; ++k) {
    const TrialResult trial = RunReferenceTrial(cube, options);
    HAPTICSIM_THROW_UNLESS(trial.outcome == TrialOutcome::kCompleted,
                           "the full-resolution reference did not complete: " +
                               std::string(TrialOutcomeName(trial.outcome)));
    costs.push_back(trial.wall_time_s * 1e6 / (trial.steps * scene.solver.dt_s * 1e3));
    *substeps = trial.substeps;
  }
  return Median(costs);
}

std::string ConfigurationName(const RegionConfiguration& c) {
  std::ostringstream name;
  name << "primary " << c.primary_size << ", lod " << c.secondary_lod << ", " << c.secondary_rate_hz
       << " Hz";
  return name.str();
}

int RunScene(const BenchOptions& o) {
  const Scene scene = o.scene.Resolve();
  // The scene's material and its own input; every configuration of the paper's adaptivity axes.
  const MapPoint at = PointOfScene(scene);
  SweepGrid grid = SceneGrid(at);
  grid.name = "bench";
  for (MapAxis axis : {MapAxis::kAmplitude, MapAxis::kFrequency}) {
    grid.axes[static_cast<int>(axis)] = {at[static_cast<int>(axis)]};
  }
  auto override_axis = [&grid](MapAxis axis, const std::string& list, const char* option) {
    if (list.empty()) return;
    std::vector<double>& values = grid.axes[static_cast<int>(axis)];
    values = ParseNumberList(list, option);
    std::sort(values.begin(), values.end());
    values.erase(std::unique(values.begin(), values.end()), values.end());
  };
  override_axis(MapAxis::kPrimarySize, o.primary_sizes, "--primary-size");
  override_axis(MapAxis::kSecondaryLod, o.secondary_lods, "--secondary-lod");
  override_axis(MapAxis::kSecondaryRate, o.secondary_rates, "--secondary-rate");
  ValidateGrid(grid);
  SweepOptions options;
  options.jobs = o.jobs;
  ProgressLine progress("bench", 10.0, "configurations");
  options.progress = [&progress](const SweepProgress& p) {
    progress.Update(p.samples_done, p.samples_total, p.samples_done, p.elapsed_s);
  };
  if (!o.scene.json) std::cerr << "bench: the full-resolution reference…\n";
  int reference_substeps = 1;
  const double reference_cost = ReferenceCostUsPerMs(scene, &reference_substeps);
  SweepStats stats;
  const ErrorMap map = RunSweep(scene, grid, options, &stats);
  progress.Finish();

  std::vector<ConfigurationResult> results;
  std::vector<TradeOff> trade_offs;
  for (const MapSample& sample : map.samples) {
    ConfigurationResult r;
    r.configuration = {static_cast<int>(sample.point[static_cast<int>(MapAxis::kPrimarySize)]),
                       static_cast<int>(sample.point[static_cast<int>(MapAxis::kSecondaryLod)]),
                       sample.point[static_cast<int>(MapAxis::kSecondaryRate)]};
    r.status = sample.status;
    r.cost_us_per_ms = sample.cost_us_per_ms;
    r.cost_us_per_ms_total = sample.total_cost_us_per_ms();
    r.primary_period_share = sample.cost_us_per_ms[0] / 1000.0;  // µs per ms of its 1 ms period
    r.l2_percent = sample.l2_percent;
    r.max_magnitude_percent = sample.max_magnitude_percent;
    try {
      const AsyncRegions regions(SceneWith(scene, r.configuration));
      for (int a = 0; a < regions.num_regions(); ++a) {
        r.substeps.push_back(regions.schedule(a).substeps);
      }
    } catch (const Error&) {
      // A configuration the regions refuse to build has no schedule; its status says why.
    }
    trade_offs.push_back(
        {r.cost_us_per_ms_total, r.l2_percent, sample.status == SampleStatus::kOk});
    results.push_back(r);
  }
  const std::vector<int> pareto = ParetoFront(trade_offs, kErrorResolution_percent);

  if (!o.plot.empty()) {
    std::vector<ScatterPoint> points;
    for (size_t i = 0; i < results.size(); ++i) {
      if (results[i].status != SampleStatus::kOk) continue;
      points.push_back(
          {results[i].cost_us_per_ms_total, results[i].l2_percent,
           std::find(pareto.begin(), pareto.end(), static_cast<int>(i)) != pareto.end(),
           ConfigurationName(results[i].configuration)});
    }
    std::ofstream file(o.plot);
    HAPTICSIM_THROW_UNLESS(file.good(), "--plot " + o.plot + ": cannot write the file");
    file << ParetoChartSvg("Run time against force error, " + std::to_string(scene.mesh.nodes) +
                               "³ nodes (" + std::to_string(results.size()) + " configurations)",
                           points, reference_cost, 7.0);
  }

  if (o.scene.json) {
    Json configurations = Json::array();
    for (const ConfigurationResult& r : results) {
      const bool ok = r.status == SampleStatus::kOk;
      configurations.push_back(
          {{"primary_size", r.configuration.primary_size},
           {"secondary_lod", r.configuration.secondary_lod},
           {"secondary_rate", r.configuration.secondary_rate_hz},
           {"status", std::string(SampleStatusName(r.status))},
           {"cost_us_per_ms", ok ? Json(r.cost_us_per_ms_total) : Json(nullptr)},
           {"cost_by_region_us_per_ms", ok ? Json(r.cost_us_per_ms) : Json(nullptr)},
           {"primary_period_share", ok ? Json(r.primary_period_share) : Json(nullptr)},
           {"l2_percent", ok ? Json(r.l2_percent) : Json(nullptr)},
           {"max_magnitude_percent", ok ? Json(r.max_magnitude_percent) : Json(nullptr)},
           {"substeps", r.substeps}});
    }
    std::cout << Json{{"nodes_per_axis", scene.mesh.nodes},
                      {"reference_cost_us_per_ms", reference_cost},
                      {"reference_substeps", reference_substeps},
                      {"configurations", configurations},
                      {"pareto", pareto},
                      {"pareto_error_resolution_percent", kErrorResolution_percent},
                      {"jobs", o.jobs},
                      {"wall_s", stats.wall_seconds}}
                     .dump(2)
              << "\n";
    return kExitOk;
  }
  std::cout << "Run time against error: " << scene.mesh.nodes << "³ nodes, " << results.size()
            << " configurations (" << map.CountStatus(SampleStatus::kOk) << " ok, "
            << map.CountStatus(SampleStatus::kPredictedUnstable)
            << " predicted unstable, not run), " << o.jobs << " job(s)\n"
            << "Full-resolution reference: " << Quantity(reference_cost, "µs")
            << " of compute per simulated ms (" << reference_substeps << " substep(s) per 1 ms)\n\n"
            << "Pareto front — the cheapest configuration for each error level:\n"
            << "  primary  lod  secondary rate    cost µs/ms   of reference   primary share   "
               "L2 error\n";
  for (int i : pareto) {
    const ConfigurationResult& r = results[static_cast<size_t>(i)];
    char line[200];
    std::snprintf(
        line, sizeof line, "  %7d  %3d  %11.0f Hz  %12.1f  %12.0f %%  %12.1f %%  %7.2f %%\n",
        r.configuration.primary_size, r.configuration.secondary_lod,
        r.configuration.secondary_rate_hz, r.cost_us_per_ms_total,
        100 * r.cost_us_per_ms_total / reference_cost, 100 * r.primary_period_share, r.l2_percent);
    std::cout << line;
  }
  if (!o.plot.empty()) std::cout << "\nPlot: " << o.plot << "\n";
  return kExitOk;
}

}  // namespace

Command AddBenchCommand(CLI::App& parent) {
  auto o = std::make_shared<BenchOptions>();
  auto nodes_text = std::make_shared<std::string>("13,25,49");
  CLI::App* app = parent.add_subcommand(
      "bench",
      "Run time against error. On a scene: every adaptive configuration of the paper's "
      "adaptivity axes (primary size 1-4, secondary lod 1-3, secondary rate 600-1000 Hz) run "
      "on the scene's material and input, its compute cost (µs per simulated ms, per region and "
      "in total; the primary's share of its 1 ms period) and its L2 force error against the "
      "full-resolution reference, and the Pareto front: the cheapest configuration for each "
      "error level. With --kernels: the matrix-free K·u against the assembled sparse product, "
      "timed side by side in one process. Absolute times depend on the machine and what else "
      "runs on it; compare ratios.");
  AddSceneOptions(app, &o->scene);
  app->add_flag("--kernels", o->kernels,
                "time K·u matrix-free against assembled instead of running a scene");
  app->add_option("--nodes", *nodes_text,
                  "--kernels: nodes per axis, comma-separated (default 13,25,49)");
  app->add_option("--seconds", o->seconds, "--kernels: timing per kernel and size, s (default 1)")
      ->check(CLI::Range(0.05, 600.0));
  app->add_option("--jobs", o->jobs,
                  "configurations run at once (default 1: costs are measured alone)")
      ->check(CLI::Range(1, 256));
  app->add_option("--plot", o->plot, "write run time against error as an SVG image (scene)");
  app->add_option("--primary-size", o->primary_sizes,
                  "scene: primary sizes to run, comma-separated (default 1,2,3,4)");
  app->add_option("--secondary-lod", o->secondary_lods,
                  "scene: secondary spacing factors, comma-separated (default 1,2,3)");
  app->add_option("--secondary-rate", o->secondary_rates,
                  "scene: secondary rates, Hz, comma-separated (default 600,700,800,900,1000)");
  return {app, [o, nodes_text] {
            if (o->kernels) {
              for (double n : ParseNumberList(*nodes_text, "--nodes")) {
                HAPTICSIM_THROW_UNLESS(n == std::round(n),
                                       "--nodes " + *nodes_text + ": sizes are whole numbers");
                o->kernel_nodes.push_back(static_cast<int>(n));
              }
              return RunKernels(*o);
            }
            return RunScene(*o);
          }};
}

}  // namespace hapticsim::cli
