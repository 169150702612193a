// hapticsim-sweep-mpi: the error-map sweep across MPI ranks. Rank r of N computes shard r+1/N
// (the same deterministic slices as `hapticsim sweep --shard`), rank 0 merges them into one map.
//
//   mpirun -np 4 hapticsim-sweep-mpi --grid paper --out paper.hsmap [--jobs 2]
//
// Each rank may run several worker threads (--jobs). Exit status as hapticsim's: 0 ok,
// 2 bad input, 1 anything else; every rank fails together.
#include <mpi.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <iostream>

#include "core/error.hpp"
#include "core/errormap/error_map_file.hpp"
#include "core/errormap/error_sweep.hpp"
#include "core/errormap/sweep_grid_file.hpp"
#include "tools/hapticsim/scene_options.hpp"

namespace {

struct Options {
  hapticsim::cli::SceneOptions scene;
  std::string grid = "quick";
  int monte_carlo = 0;
  std::uint64_t seed = 1;
  int jobs = 1;
  std::string out = "error-map.hsmap";
  bool no_linearity = false;
  bool no_similarity = false;
};

int Sweep(const Options& o, int rank, int size) {
  using namespace hapticsim;
  const Scene scene = o.scene.Resolve();
  const SweepGrid grid = ChooseSweepGrid(o.grid, o.monte_carlo, o.seed, scene);
  SweepOptions options;
  options.jobs = o.jobs;
  options.shard_index = rank;
  options.shard_count = size;
  options.use_linearity = !o.no_linearity;
  options.use_similarity = !o.no_similarity;
  const std::string shard_path =
      o.out + ".rank" + std::to_string(rank) + "of" + std::to_string(size);
  if (rank == 0) {
    options.progress = [](const SweepProgress& p) {
      std::fprintf(stderr, "rank 0: %zu/%zu samples of its shard, %.0f s\n", p.samples_done,
                   p.samples_total, p.elapsed_s);
    };
    options.progress_interval_s = 10;
  }
  SweepStats stats;
  SaveErrorMap(RunSweep(scene, grid, options, &stats), shard_path);
  std::fprintf(stderr, "rank %d of %d: %zu samples in %.1f s\n", rank, size, stats.samples,
               stats.wall_seconds);
  MPI_Barrier(MPI_COMM_WORLD);
  if (rank != 0) return 0;
  std::vector<ErrorMap> shards;
  for (int r = 0; r < size; ++r) {
    const std::string path = o.out + ".rank" + std::to_string(r) + "of" + std::to_string(size);
    shards.push_back(LoadErrorMap(path));
    std::filesystem::remove(path);
  }
  const ErrorMap merged = MergeErrorMaps(shards);
  SaveErrorMap(merged, o.out);
  std::printf(
      "{\"map\": \"%s\", \"ranks\": %d, \"samples\": %zu, \"not_computed\": %zu, "
      "\"results_checksum\": %llu}\n",
      o.out.c_str(), size, merged.samples.size(), merged.CountStatus(SampleStatus::kNotComputed),
      static_cast<unsigned long long>(merged.ResultsChecksum()));
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  Options o;
  CLI::App app{
      "hapticsim-sweep-mpi: hapticsim sweep across MPI ranks (one shard per rank, "
      "merged by rank 0)",
      "hapticsim-sweep-mpi"};
  hapticsim::cli::AddSceneOptions(&app, &o.scene);
  app.add_option("--grid", o.grid, "paper, quick, scene or FILE.toml")->capture_default_str();
  app.add_option("--monte-carlo", o.monte_carlo, "N scattered points instead of a grid");
  app.add_option("--seed", o.seed, "Seed of --monte-carlo")->capture_default_str();
  app.add_option("--jobs,-j", o.jobs, "Worker threads per rank")->capture_default_str();
  app.add_option("--out,-o", o.out, "Merged map to write")->capture_default_str();
  app.add_flag("--no-linearity", o.no_linearity, "Run every amplitude");
  app.add_flag("--no-similarity", o.no_similarity,
               "Run every material (equal E/ρ, ν, d and contrast too)");
  int status = 0;
  try {
    app.parse(argc, argv);
    status = Sweep(o, rank, size);
  } catch (const CLI::ParseError& e) {
    status = rank == 0 ? app.exit(e) : (e.get_exit_code() == 0 ? 0 : 2);
    if (e.get_exit_code() != 0) status = 2;
  } catch (const hapticsim::Error& e) {
    std::fprintf(stderr, "hapticsim-sweep-mpi (rank %d): error: %s\n", rank, e.what());
    status = 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hapticsim-sweep-mpi (rank %d): internal error: %s\n", rank, e.what());
    status = 1;
  }
  if (status != 0 && size > 1) MPI_Abort(MPI_COMM_WORLD, status);
  MPI_Finalize();
  return status;
}
