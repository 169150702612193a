// The run-time error lookup on a map the size of the paper's grid (77,760 points), and loading
// one lookup table (with the samples' status) from disk: both must fit the daemon's budgets (a
// lookup per 1 kHz period, a load well under a millisecond per table).
#include <benchmark/benchmark.h>

#include <filesystem>

#include "core/errormap/error_lookup.hpp"
#include "core/errormap/error_map_file.hpp"
#include "core/errormap/sweep_grid.hpp"

namespace hapticsim {
namespace {

ErrorMap PaperSizedMap() {
  ErrorMap map = ErrorMap::MakeGrid(PaperGrid(PointOfScene(Scene{})).axes);
  for (size_t i = 0; i < map.samples.size(); ++i) {
    map.samples[i].status = SampleStatus::kOk;
    map.samples[i].l2_percent = static_cast<double>(i % 89) / 10;
    map.samples[i].max_magnitude_percent = static_cast<double>(i % 97) / 10;
  }
  map.provenance.grid = "benchmark";
  return map;
}

// A query between grid points on every continuous axis: 2^7 corners.
MapPoint BetweenGridPoints() { return {0.43, 900, 15, 12000, 0.007, 0.8, 2, 3, 750}; }

void BM_LookupPoint(benchmark::State& state) {
  const ErrorLookup lookup(PaperSizedMap(), ErrorField::kMagnitude);
  const LookupQuery query = LookupQuery::At(BetweenGridPoints());
  for (auto _ : state) benchmark::DoNotOptimize(lookup.Lookup(query));
}

// The supervisor's question: heterogeneous material (ν, E ranges) and an unknown frequency.
void BM_LookupWorstCaseBox(benchmark::State& state) {
  const ErrorLookup lookup(PaperSizedMap(), ErrorField::kMagnitude);
  LookupQuery query = LookupQuery::At(BetweenGridPoints());
  query.lo[0] = 0.42, query.hi[0] = 0.47;
  query.lo[3] = 8000, query.hi[3] = 16000;
  query.frequency_known = false;
  for (auto _ : state) benchmark::DoNotOptimize(lookup.Lookup(query));
}

void BM_LoadLookupTable(benchmark::State& state) {
  const std::string path =
      (std::filesystem::temp_directory_path() / "hapticsim_benchmark.hsmap").string();
  SaveErrorMap(PaperSizedMap(), path);
  for (auto _ : state) {
    benchmark::DoNotOptimize(LoadErrorLookup(path, ErrorField::kMagnitude));
  }
  std::filesystem::remove(path);
}

BENCHMARK(BM_LookupPoint)->Unit(benchmark::kNanosecond);
BENCHMARK(BM_LookupWorstCaseBox)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_LoadLookupTable)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace hapticsim

BENCHMARK_MAIN();
