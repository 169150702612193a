#include <csignal>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <thread>

#include "core/error.hpp"
#include "core/errormap/error_map_file.hpp"
#include "core/errormap/error_sweep.hpp"
#include "core/errormap/sweep_grid_file.hpp"
#include "tools/hapticsim/command.hpp"
#include "tools/hapticsim/format.hpp"
#include "tools/hapticsim/progress_line.hpp"
#include "tools/hapticsim/scene_options.hpp"
#include "tools/hapticsim/stepping_order_option.hpp"

namespace hapticsim::cli {
namespace {

std::atomic<bool> g_stop{false};
extern "C" void OnInterrupt(int) { g_stop = true; }

struct SweepCommandOptions {
  SceneOptions scene;
  std::string grid = "quick";
  int monte_carlo = 0;
  std::uint64_t seed = 1;
  int jobs = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  std::string out = "error-map.hsmap";
  bool resume = false;
  std::string shard = "1/1";
  bool no_linearity = false;
  bool no_similarity = false;
  SteppingOrder order = SteppingOrder::kThreads;  // hapticsimd's, whose force the map judges
};

std::pair<int, int> ParseShard(const std::string& text) {
  int index = 0, count = 0;
  char slash = 0, extra = 0;
  if (std::sscanf(text.c_str(), "%d%c%d%c", &index, &slash, &count, &extra) != 3 || slash != '/' ||
      count < 1 || index < 1 || index > count) {
    throw hapticsim::Error("--shard " + text + ": expected I/N with 1 ≤ I ≤ N, e.g. --shard 2/4");
  }
  return {index - 1, count};
}

nlohmann::json StatsJson(const SweepStats& s, const ErrorMap& map) {
  return {{"samples", s.samples},
          {"samples_resumed", s.samples_resumed},
          {"ok", map.CountStatus(SampleStatus::kOk)},
          {"predicted_unstable", map.CountStatus(SampleStatus::kPredictedUnstable)},
          {"diverged", map.CountStatus(SampleStatus::kDiverged)},
          {"not_computed", map.CountStatus(SampleStatus::kNotComputed)},
          {"tasks", s.tasks},
          {"reference_trials", s.reference_trials},
          {"adaptive_trials", s.adaptive_trials},
          {"stability_estimates", s.stability_estimates},
          {"saved",
           {{"reference_reuse_trials", s.saved_by_reference_reuse},
            {"similarity_trials", s.saved_by_similarity},
            {"linearity_trials", s.saved_by_linearity},
            {"same_regions_trials", s.saved_by_same_regions},
            {"predicted_unstable_trials", s.saved_by_prediction}}},
          {"cpu_s",
           {{"reference", s.reference_seconds},
            {"adaptive", s.adaptive_seconds},
            {"stability", s.stability_seconds}}},
          {"wall_s", s.wall_seconds},
          {"results_checksum", map.ResultsChecksum()}};
}

int Run(const SweepCommandOptions& o) {
  const Scene scene = o.scene.Resolve();
  const SweepGrid grid = ChooseSweepGrid(o.grid, o.monte_carlo, o.seed, scene);
  const auto [shard_index, shard_count] = ParseShard(o.shard);
  SweepOptions options;
  options.jobs = o.jobs;
  options.shard_index = shard_index;
  options.shard_count = shard_count;
  options.use_linearity = !o.no_linearity;
  options.use_similarity = !o.no_similarity;
  options.order = o.order;
  options.journal_path = o.out + ".journal";
  options.resume = o.resume;
  options.stop = &g_stop;
  ProgressLine progress("sweep " + grid.name);
  options.progress = [&progress](const SweepProgress& p) {
    progress.Update(p.samples_done, p.samples_total, p.samples_done - p.samples_resumed,
                    p.elapsed_s);
  };
  if (!o.resume && std::filesystem::exists(options.journal_path)) {
    std::cerr << "hapticsim sweep: starting afresh; " << options.journal_path
              << " from an earlier run is replaced (use --resume to continue it)\n";
  }
  std::signal(SIGINT, OnInterrupt);
  std::signal(SIGTERM, OnInterrupt);
  SweepStats stats;
  const ErrorMap map = RunSweep(scene, grid, options, &stats);
  progress.Finish();
  std::signal(SIGINT, SIG_DFL);
  std::signal(SIGTERM, SIG_DFL);
  if (stats.interrupted) {
    std::cerr << "hapticsim sweep: interrupted; completed samples are kept in "
              << options.journal_path << ". Run the same command with --resume to go on.\n";
    return 130;
  }
  SaveErrorMap(map, o.out);
  std::filesystem::remove(options.journal_path);
  if (o.scene.json) {
    nlohmann::json out = StatsJson(stats, map);
    out["map"] = o.out;
    out["grid"] = grid.name;
    out["shard"] = map.provenance.shard;
    out["jobs"] = o.jobs;
    std::cout << out.dump(2) << "\n";
    return kExitOk;
  }
  std::cout << "Error map " << o.out << ": " << stats.samples << " samples (grid " << grid.name
            << ", shard " << map.provenance.shard << ") in " << ShortDuration(stats.wall_seconds)
            << " on " << o.jobs << " jobs\n"
            << "  ok " << map.CountStatus(SampleStatus::kOk) << ", diverged "
            << map.CountStatus(SampleStatus::kDiverged) << "\n"
            << "  runs made: " << stats.reference_trials << " references, " << stats.adaptive_trials
            << " adaptive trials"
            << (stats.samples_resumed ? ", " + std::to_string(stats.samples_resumed) +
                                            " samples resumed from the journal"
                                      : "")
            << "\n"
            << "  runs saved: " << stats.saved_by_reference_reuse << " references (reuse), "
            << stats.saved_by_similarity << " adaptive (materials of equal E/ρ, ν, d, contrast), "
            << stats.saved_by_linearity << " adaptive (linearity in amplitude), "
            << stats.saved_by_same_regions << " adaptive (sizes giving the same regions)\n"
            << "  CPU time: references " << Duration(stats.reference_seconds) << ", adaptive "
            << Duration(stats.adaptive_seconds) << "\n";
  return kExitOk;
}

}  // namespace

Command AddSweepCommand(CLI::App& parent) {
  auto o = std::make_shared<SweepCommandOptions>();
  CLI::App* app = parent.add_subcommand(
      "sweep",
      "Make an error map: adaptive runs over material, input and adaptivity compared with the "
      "full-resolution reference (the paper's Section V). Progress on stderr; Ctrl-C keeps what "
      "is done for --resume.");
  AddSceneOptions(app, &o->scene);
  app->add_option(
         "--grid", o->grid,
         "paper (the paper's 77,760 points), quick (2 values per parameter, 2 contact nodes; "
         "under a minute on the cube), "
         "scene (the scene's material, all inputs and configurations: the daemon's map) "
         "or FILE.toml ([axes] lists)")
      ->capture_default_str();
  app->add_option("--monte-carlo", o->monte_carlo,
                  "Instead of a grid: N points drawn from the paper's ranges (a scattered map, for "
                  "analysis; lookup needs a grid)")
      ->type_name("N");
  app->add_option("--seed", o->seed, "Random seed of --monte-carlo")->capture_default_str();
  app->add_option("--jobs,-j", o->jobs, "Worker threads")
      ->capture_default_str()
      ->check(CLI::Range(1, 256));
  app->add_option("--out,-o", o->out, "Map file to write")->capture_default_str();
  app->add_flag("--resume", o->resume,
                "Continue an interrupted sweep from OUT.journal (same command otherwise)");
  app->add_option("--shard", o->shard,
                  "Compute slice I of N (1-based) of the task list; join with hapticsim map merge")
      ->capture_default_str();
  app->add_flag("--no-linearity", o->no_linearity,
                "Run every amplitude instead of deriving the amplitude axis from linearity");
  app->add_flag("--no-similarity", o->no_similarity,
                "Run every material instead of deriving a material of the same E/ρ, ν, d and "
                "contrast as an earlier one from it (its forces scaled by the density ratio)");
  AddSteppingOrderOption(app, &o->order,
                         "How the trials step the regions: 'threads' (as hapticsimd's threads do, "
                         "so the map holds the error of the force the daemon renders) or "
                         "'substeps' (the secondaries before each primary substep: where a "
                         "secondary runs at another rate in several substeps, an exchange the "
                         "daemon does not run; docs/regions.md). The map says which");
  return {app, [o] { return Run(*o); }};
}

}  // namespace hapticsim::cli
