#include "core/errormap/error_sweep.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "core/regions/async_regions.hpp"
#include "core/error.hpp"
#include "core/errormap/error_lookup.hpp"
#include "core/errormap/error_map_file.hpp"

namespace hapticsim {
namespace {

constexpr int kDamping = 2, kAmplitude = 4, kSize = 7, kRate = 8;

// A 9³ cube and a grid small enough to sweep several times per test, still with two values on
// the axes each shortcut works on: amplitude (linearity), primary size 1 and 2 (the same regions
// at spacing factor 2) and rate.
Scene SmallScene() {
  Scene scene;
  scene.mesh.nodes = 9;
  scene.input.frequency_hz = 2.0;
  return scene;
}

SweepGrid SmallGrid() {
  SweepGrid grid;
  grid.name = "test";
  const MapPoint base = PointOfScene(SmallScene());
  for (int a = 0; a < kNumMapAxes; ++a) grid.axes[a] = {base[a]};
  grid.axes[kDamping] = {10, 30};
  grid.axes[kAmplitude] = {0.005, 0.01};
  grid.axes[6] = {2};
  grid.axes[kSize] = {1, 2};
  grid.axes[kRate] = {600, 1000};
  return grid;
}

ErrorMap Sweep(const SweepGrid& grid, SweepOptions options = {}, SweepStats* stats = nullptr) {
  SweepStats local;
  return RunSweep(SmallScene(), grid, options, stats ? stats : &local);
}

TEST(ErrorSweep, EverySampleIsComputedAndTheResultDoesNotDependOnTheJobCount) {
  SweepOptions one, two;
  two.jobs = 2;
  const ErrorMap a = Sweep(SmallGrid(), one), b = Sweep(SmallGrid(), two);
  EXPECT_EQ(a.samples.size(), 16u);
  EXPECT_EQ(a.CountStatus(SampleStatus::kNotComputed), 0u);
  EXPECT_GE(a.CountStatus(SampleStatus::kOk), a.samples.size() / 2) << "most samples ran";
  EXPECT_EQ(a.ResultsChecksum(), b.ResultsChecksum());
  for (const MapSample& s : a.samples) {
    if (s.status != SampleStatus::kOk) continue;
    EXPECT_GT(s.reference_peak_n, 0);
    EXPECT_GT(s.cost_us_per_ms[0], 0);  // the primary region was timed
    EXPECT_TRUE(std::isfinite(s.l2_percent));
  }
}

TEST(ErrorSweep, AStrokeSceneIsRefusedSayingWhatToSweep) {
  Scene stroke = SmallScene();
  stroke.input.waveform = Waveform::kStroke;
  SweepStats stats;
  try {
    RunSweep(stroke, SmallGrid(), {}, &stats);
    FAIL() << "a stroke scene was swept";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("set input.waveform = \"press\""), std::string::npos)
        << e.what();
  }
}

// The daemon's sliding tool (contact.model = "proxy") shares the press's map: its scene sweeps
// to the same map as the node contact's.
TEST(ErrorSweep, ASlidingToolsSceneSweepsThePressesOfItsObject) {
  Scene proxy = SmallScene();
  proxy.contact.model = ContactModel::kProxy;
  SweepStats stats;
  const ErrorMap sliding = RunSweep(proxy, SmallGrid(), {}, &stats);
  const ErrorMap node = RunSweep(SmallScene(), SmallGrid(), {}, &stats);
  ASSERT_EQ(sliding.samples.size(), node.samples.size());
  for (std::size_t i = 0; i < node.samples.size(); ++i) {
    EXPECT_TRUE(node.samples[i].computed()) << "sample " << i;
    EXPECT_EQ(sliding.samples[i].l2_percent, node.samples[i].l2_percent) << "sample " << i;
    EXPECT_EQ(sliding.samples[i].status, node.samples[i].status) << "sample " << i;
  }
}

TEST(ErrorSweep, EqualRatesAtFullResolutionReproduceTheReference) {
  SweepGrid grid = SmallGrid();
  grid.axes[6] = {1};
  grid.axes[kRate] = {1000};
  const ErrorMap map = Sweep(grid);
  for (const MapSample& s : map.samples) {
    ASSERT_EQ(s.status, SampleStatus::kOk);
    EXPECT_LT(s.l2_percent, 1e-6);  // monolithic central difference: round-off only
  }
}

TEST(ErrorSweep, AmplitudeFromLinearityMatchesRunningEveryAmplitude) {
  SweepOptions derived, run_all;
  run_all.use_linearity = false;
  SweepStats derived_stats, run_all_stats;
  const ErrorMap a = Sweep(SmallGrid(), derived, &derived_stats);
  const ErrorMap b = Sweep(SmallGrid(), run_all, &run_all_stats);
  EXPECT_TRUE(a.provenance.linearity_used);
  EXPECT_FALSE(b.provenance.linearity_used);
  EXPECT_GT(derived_stats.saved_by_linearity, 0u);
  EXPECT_EQ(run_all_stats.saved_by_linearity, 0u);
  EXPECT_EQ(run_all_stats.adaptive_trials, 2 * derived_stats.adaptive_trials);
  EXPECT_GE(a.CountStatus(SampleStatus::kOk), a.samples.size() / 2) << "most samples ran";
  for (size_t i = 0; i < a.samples.size(); ++i) {
    const MapSample &x = a.samples[i], &y = b.samples[i];
    ASSERT_EQ(x.status, y.status);
    if (x.status != SampleStatus::kOk) continue;
    EXPECT_NEAR(x.l2_percent, y.l2_percent, 1e-9 * y.l2_percent + 1e-12);
    EXPECT_NEAR(x.max_magnitude_percent, y.max_magnitude_percent,
                1e-9 * y.max_magnitude_percent + 1e-12);
    EXPECT_NEAR(x.reference_peak_n, y.reference_peak_n, 1e-12 * y.reference_peak_n);
  }
}

// Dynamic similarity: ρü + ρd·u̇ + E·K̂u = 0 with the contact's motion prescribed moves the same
// for E/ρ = 10 kPa / 800 kg/m³ = 15 kPa / 1200 kg/m³, with 1.5 × the force at the denser. Run
// once and scaled, the samples equal those of running both; the material of another E/ρ differs.
TEST(ErrorSweep, AMaterialOfTheSameWaveSpeedIsTheEarlierOneScaledByItsDensity) {
  constexpr int kDensity = 1, kYoungs = 3;
  SweepGrid grid = SmallGrid();
  grid.axes[kDamping] = {10};
  grid.axes[kSize] = {1};
  grid.axes[kDensity] = {800, 1200};
  grid.axes[kYoungs] = {10000, 15000};
  SweepOptions derived, run_all;
  run_all.use_similarity = false;
  SweepStats derived_stats, run_all_stats;
  const ErrorMap a = Sweep(grid, derived, &derived_stats);
  const ErrorMap b = Sweep(grid, run_all, &run_all_stats);
  ASSERT_EQ(a.samples.size(), 16u);
  EXPECT_EQ(derived_stats.saved_by_similarity, 4u);  // (1200, 15 kPa): 2 amplitudes × 2 rates
  EXPECT_EQ(run_all_stats.saved_by_similarity, 0u);
  EXPECT_EQ(derived_stats.adaptive_trials, 6u);
  EXPECT_EQ(run_all_stats.adaptive_trials, 8u);
  EXPECT_EQ(derived_stats.stability_estimates, 0u);  // passive by construction: none needed
  EXPECT_EQ(derived_stats.reference_trials, 3u);
  EXPECT_EQ(run_all_stats.reference_trials, 4u);
  auto at = [&](const ErrorMap& map, double density, double youngs, double amplitude,
                double rate) -> const MapSample& {
    for (const MapSample& s : map.samples) {
      if (s.point[kDensity] == density && s.point[kYoungs] == youngs &&
          s.point[kAmplitude] == amplitude && s.point[kRate] == rate) {
        return s;
      }
    }
    throw Error("no such sample");
  };
  for (double amplitude : grid.axes[kAmplitude]) {
    for (double rate : grid.axes[kRate]) {
      const MapSample& light = at(b, 800, 10000, amplitude, rate);
      const MapSample& dense = at(b, 1200, 15000, amplitude, rate);
      const MapSample& derived_dense = at(a, 1200, 15000, amplitude, rate);
      const MapSample& other = at(b, 1200, 10000, amplitude, rate);  // E/ρ = 8.3 m²/s²
      ASSERT_EQ(light.status, SampleStatus::kOk);
      // Running both: the physics says they are similar (the code knows nothing of it).
      ASSERT_EQ(dense.status, SampleStatus::kOk);
      EXPECT_NEAR(dense.l2_percent, light.l2_percent, 1e-9 * light.l2_percent);
      EXPECT_NEAR(dense.max_magnitude_percent, light.max_magnitude_percent,
                  1e-9 * light.max_magnitude_percent);
      EXPECT_NEAR(dense.max_direction_deg, light.max_direction_deg, 1e-6);
      EXPECT_NEAR(dense.reference_peak_n, 1.5 * light.reference_peak_n,
                  1e-9 * dense.reference_peak_n);
      EXPECT_TRUE(std::isnan(dense.spectral_radius));  // not estimated
      // Derived: the same as running it.
      ASSERT_EQ(derived_dense.status, dense.status);
      EXPECT_NEAR(derived_dense.l2_percent, dense.l2_percent, 1e-9 * dense.l2_percent);
      EXPECT_NEAR(derived_dense.max_magnitude_percent, dense.max_magnitude_percent,
                  1e-9 * dense.max_magnitude_percent);
      EXPECT_NEAR(derived_dense.reference_peak_n, dense.reference_peak_n,
                  1e-9 * dense.reference_peak_n);
      // Another wave speed is another answer: the comparison above can tell.
      ASSERT_EQ(other.status, SampleStatus::kOk);
      EXPECT_GT(std::abs(other.l2_percent - light.l2_percent), 1e-3 * light.l2_percent);
    }
  }
  // Every other sample is the same whichever way it was made.
  for (size_t i = 0; i < a.samples.size(); ++i) {
    ASSERT_EQ(a.samples[i].status, b.samples[i].status) << i;
    if (a.samples[i].status != SampleStatus::kOk) continue;
    EXPECT_NEAR(a.samples[i].l2_percent, b.samples[i].l2_percent, 1e-9 * b.samples[i].l2_percent);
  }
}

TEST(ErrorSweep, SizesGivingTheSameRegionsAreRunOnceWithTheSameAnswer) {
  SweepStats stats;
  const ErrorMap both = Sweep(SmallGrid(), {}, &stats);
  EXPECT_GT(stats.saved_by_same_regions, 0u);  // sizes 1 and 2 round to the same coarse cells
  SweepGrid only_two = SmallGrid();
  only_two.axes[kSize] = {2};
  const ErrorMap alone = Sweep(only_two);
  for (const MapSample& s : alone.samples) {
    const auto match = std::find_if(both.samples.begin(), both.samples.end(),
                                    [&](const MapSample& t) { return t.point == s.point; });
    ASSERT_NE(match, both.samples.end());
    EXPECT_EQ(match->status, s.status);
    if (s.status == SampleStatus::kOk) {
      EXPECT_EQ(match->l2_percent, s.l2_percent);
    }
  }
}

TEST(ErrorSweep, ShardsMergeIntoTheWholeMap) {
  SweepStats whole_stats;
  const ErrorMap whole = Sweep(SmallGrid(), {}, &whole_stats);
  std::vector<ErrorMap> shards;
  std::size_t linearity = 0, same_regions = 0;  // what the shards say they saved, summed
  for (int i = 0; i < 3; ++i) {
    SweepOptions options;
    options.shard_index = i;
    options.shard_count = 3;
    SweepStats stats;
    shards.push_back(Sweep(SmallGrid(), options, &stats));
    linearity += stats.saved_by_linearity;
    same_regions += stats.saved_by_same_regions;
    EXPECT_GT(shards.back().CountStatus(SampleStatus::kNotComputed), 0u);
  }
  EXPECT_EQ(linearity, whole_stats.saved_by_linearity);
  EXPECT_EQ(same_regions, whole_stats.saved_by_same_regions);
  const ErrorMap merged = MergeErrorMaps(shards);
  EXPECT_EQ(merged.CountStatus(SampleStatus::kNotComputed), 0u);
  EXPECT_EQ(merged.ResultsChecksum(), whole.ResultsChecksum());
  EXPECT_EQ(merged.provenance.shard, "1/1");
  shards[1].provenance.scene_toml += "# another scene\n";
  EXPECT_THROW(MergeErrorMaps(shards), Error);
}

TEST(ErrorSweep, AResumedSweepSkipsJournalledTasksAndEndsWithTheSameMap) {
  const std::string journal =
      (std::filesystem::temp_directory_path() / "hapticsim_sweep_test.journal").string();
  SweepOptions options;
  options.journal_path = journal;
  const ErrorMap whole = Sweep(SmallGrid(), options);
  // Keep the header and two tasks, and tear the third line as a crash mid-write would.
  std::vector<std::string> lines;
  {
    std::ifstream in(journal);
    for (std::string line; std::getline(in, line);) lines.push_back(line);
  }
  ASSERT_GE(lines.size(), 4u);
  {
    std::ofstream out(journal, std::ios::trunc);
    out << lines[0] << "\n"
        << lines[1] << "\n"
        << lines[2] << "\n"
        << lines[3].substr(0, lines[3].size() / 2);
  }
  options.resume = true;
  SweepStats stats;
  const ErrorMap resumed = Sweep(SmallGrid(), options, &stats);
  EXPECT_GT(stats.samples_resumed, 0u);
  EXPECT_LT(stats.samples_resumed, stats.samples);
  EXPECT_EQ(resumed.ResultsChecksum(), whole.ResultsChecksum());

  // A journal of another sweep is refused, not mixed in.
  SweepGrid other = SmallGrid();
  other.axes[kRate] = {700, 1000};
  EXPECT_THROW(Sweep(other, options), Error);
  std::filesystem::remove(journal);
}

TEST(ErrorSweep, AStopRequestEndsTheSweepWithoutComputingMore) {
  std::atomic<bool> stop{true};
  SweepOptions options;
  options.stop = &stop;
  SweepStats stats;
  const ErrorMap map = Sweep(SmallGrid(), options, &stats);
  EXPECT_TRUE(stats.interrupted);
  EXPECT_EQ(map.CountStatus(SampleStatus::kNotComputed), map.samples.size());
}

// The contact-node axes: every node is swept as a scene driven at that node. Checked against the
// cube's mirror symmetry x → L − x (the supports, the four back corners, are invariant under it;
// no code path knows about it): nodes mirrored about the middle must give the same errors and
// peak force. And a node's samples must be those of a sweep whose scene is driven there.
TEST(ErrorSweep, EachContactNodeIsSweptAsItsOwnSceneAndMirroredNodesAgree) {
  constexpr int kX = static_cast<int>(MapAxis::kContactNodeX);
  SweepGrid grid = SmallGrid();
  grid.axes[kDamping] = {10};
  grid.axes[kAmplitude] = {0.01};
  grid.axes[kSize] = {1};
  grid.axes[kX] = {2, 4, 6};  // the 9³ cube's middle is x = 4
  SweepOptions options;
  options.jobs = 2;
  SweepStats stats;
  const ErrorMap map = Sweep(grid, options, &stats);
  EXPECT_EQ(stats.reference_trials, 3u);  // one per node: a node's force is its own
  ASSERT_EQ(map.samples.size(), 6u);      // nodes × rates {600, 1000}
  auto at = [&](double x, double rate) -> const MapSample& {
    for (const MapSample& s : map.samples) {
      if (s.point[kX] == x && s.point[kRate] == rate) return s;
    }
    throw Error("no sample");
  };
  for (double rate : {600.0, 1000.0}) {
    const MapSample &left = at(2, rate), &middle = at(4, rate), &right = at(6, rate);
    ASSERT_EQ(left.status, SampleStatus::kOk);
    ASSERT_EQ(right.status, SampleStatus::kOk);
    EXPECT_NEAR(left.reference_peak_n, right.reference_peak_n, 1e-9 * left.reference_peak_n);
    EXPECT_NEAR(left.l2_percent, right.l2_percent, 1e-6 * (1 + left.l2_percent));
    EXPECT_NEAR(left.max_magnitude_percent, right.max_magnitude_percent,
                1e-6 * (1 + left.max_magnitude_percent));
    EXPECT_NE(left.reference_peak_n, middle.reference_peak_n);  // the node changes the scene
  }
  // The node x = 2 alone, as the scene's own contact node: the same numbers.
  Scene at_two = SmallScene();
  at_two.input.contact_node = LatticeIndex{2, 4, 0};
  SweepGrid single = grid;
  single.axes[kX] = {2};
  SweepStats single_stats;
  const ErrorMap alone = RunSweep(at_two, single, options, &single_stats);
  for (const MapSample& s : alone.samples) {
    const MapSample& swept = at(2, s.point[kRate]);
    EXPECT_EQ(s.status, swept.status);
    EXPECT_EQ(s.reference_peak_n, swept.reference_peak_n);
    EXPECT_EQ(s.l2_percent, swept.l2_percent);
  }
}

TEST(ErrorSweep, MonteCarloPointsAreReproducibleAndInsideThePapersRanges) {
  const MapPoint at = PointOfScene(Scene{});
  const SweepGrid a = MonteCarloGrid(200, 42, at), b = MonteCarloGrid(200, 42, at);
  const SweepGrid c = MonteCarloGrid(200, 43, at);
  EXPECT_EQ(a.points, b.points);
  EXPECT_NE(a.points, c.points);
  const SweepGrid paper = PaperGrid(at);
  for (const MapPoint& p : a.points) {
    for (int axis = 0; axis < kNumMapAxes; ++axis) {
      const auto& values = paper.axes[axis];
      EXPECT_GE(p[axis], values.front());
      EXPECT_LE(p[axis], values.back());
      if (AxisInfo(axis).integer) {
        EXPECT_NE(std::find(values.begin(), values.end(), p[axis]), values.end());
      }
    }
  }
}

TEST(ErrorSweep, AMonteCarloSweepMakesAScatteredMapThatCannotBeLookedUp) {
  SweepGrid grid = MonteCarloGrid(3, 7, PointOfScene(SmallScene()));
  for (MapPoint& p : grid.points) p[6] = 2, p[7] = 1;  // spacing factor 2: valid on the 9³ cube
  SweepOptions options;
  options.jobs = 2;
  const ErrorMap map = Sweep(grid, options);
  EXPECT_FALSE(map.grid);
  EXPECT_EQ(map.CountStatus(SampleStatus::kNotComputed), 0u);
  for (size_t i = 0; i < grid.points.size(); ++i) EXPECT_EQ(map.samples[i].point, grid.points[i]);
  EXPECT_THROW(ErrorLookup(map, ErrorField::kL2), Error);
}

}  // namespace
}  // namespace hapticsim
