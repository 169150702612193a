#include "core/errormap/error_sweep.hpp"

#include <chrono>
#include <cstdio>
#include <limits>
#include <map>
#include <mutex>
#include <utility>
#include <vector>

#include "core/error.hpp"
#include "core/errormap/parallel_for.hpp"
#include "core/errormap/sweep_journal.hpp"
#include "core/errormap/sweep_plan.hpp"
#include "core/fnv1a.hpp"
#include "core/regions/async_regions.hpp"
#include "core/scene/scene_model.hpp"
#include "core/scene/scene_toml.hpp"
#include "core/trial/force_error.hpp"
#include "core/trial/reference_trial.hpp"

#ifndef HAPTICSIM_CODE_VERSION
#define HAPTICSIM_CODE_VERSION "unknown"
#endif

namespace hapticsim {
namespace {

using Clock = std::chrono::steady_clock;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Time in a worker between two points: CPU time while the machine is not oversubscribed.
double SecondsSince(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

struct Reference {
  MapPoint point{};  // a run that needs it: its configuration axes are not used
  TrialResult trial;
  bool ok = false;
};
using References = std::map<ReferenceKey, Reference>;
using PlacedSamples = std::vector<std::pair<std::size_t, MapSample>>;

// The base scene as the map records it. On a geometry: its contact node resolved (a lookup of
// the map's own node need not build the object), and a hash of the voxels the file held, as a
// comment, so that a shard, a journal or a map of another file's object is not taken for this
// one (merge and --resume compare the recorded scene).
std::string RecordedScene(const Scene& base) {
  if (!base.geometry.from_file()) return FormatSceneToml(base);
  Scene resolved = base;
  resolved.input.contact_node = SceneContactNode(base);
  std::string comment;
  if (base.loaded_geometry) {
    const LabelVolume& v = base.loaded_geometry->voxels;
    Fnv1a hash;
    hash.Bytes(v.voxels.data(), sizeof v.voxels);
    hash.Bytes(&v.spacing_m, sizeof v.spacing_m);
    hash.Bytes(v.labels.data(), v.labels.size() * sizeof v.labels[0]);
    char text[96];
    std::snprintf(text, sizeof text, "# geometry.file's voxels: FNV-1a %016llx\n",
                  static_cast<unsigned long long>(hash.value()));
    comment = text;
  }
  return comment + FormatSceneToml(resolved);
}

// The map the sweep fills: every sample's point, no result yet, and where it comes from.
ErrorMap EmptyMap(const Scene& base, const SweepGrid& grid, const SweepOptions& options,
                  const ModelTraits& model, bool linear) {
  ErrorMap map;
  if (grid.scattered) {
    map.grid = false;
    map.samples.resize(grid.points.size());
    for (size_t i = 0; i < grid.points.size(); ++i) map.samples[i].point = grid.points[i];
  } else {
    map = ErrorMap::MakeGrid(grid.axes);
  }
  map.provenance.scene_toml = RecordedScene(base);
  map.provenance.model = model.name;
  map.provenance.code_version = CodeVersion();
  map.provenance.grid = grid.name;
  map.provenance.shard =
      std::to_string(options.shard_index + 1) + "/" + std::to_string(options.shard_count);
  map.provenance.direction_threshold = ForceError::kDirectionThreshold;
  map.provenance.linearity_used = linear;
  map.provenance.stepping_order = std::string(SteppingOrderName(options.order));
  for (const MapSample& s : map.samples) SceneAtPoint(base, s.point);  // validates every point
  return map;
}

// Phase 1: one full-resolution reference per material and input that the tasks `todo` need.
References RunReferences(const Scene& base, const std::vector<SweepTask>& tasks,
                         const std::vector<std::size_t>& todo, const SweepOptions& options,
                         const std::function<void()>& tick, SweepStats* stats) {
  References references;
  std::size_t reference_uses = 0;
  for (std::size_t t : todo) {
    for (const SweepRun& run : tasks[t].runs)
      references[ReferenceKeyOf(run.point)].point = run.point;
    reference_uses += tasks[t].runs.size();
  }
  std::vector<Reference*> list;
  for (auto& entry : references) list.push_back(&entry.second);
  std::mutex stats_mutex;
  ParallelFor(
      list.size(), options.jobs, options.stop,
      [&](std::size_t i) {
        Reference& reference = *list[i];
        Scene scene = SceneAtPoint(base, reference.point);
        scene.adaptivity.primary_size = 0;
        TrialOptions trial_options;
        trial_options.substep_to_stability = true;
        const auto t0 = Clock::now();
        reference.trial = RunReferenceTrial(SceneModel(scene), trial_options);
        reference.ok = reference.trial.outcome == TrialOutcome::kCompleted;
        std::lock_guard lock(stats_mutex);
        stats->reference_seconds += SecondsSince(t0);
      },
      tick, options.progress_interval_s);
  stats->reference_trials = references.size();
  stats->saved_by_reference_reuse = reference_uses - references.size();
  return references;
}

// One run's sample: the adaptive run of `regions` for the run's input, compared with its
// reference; its cost per region. `adaptive_s` and `trials` count what was run.
MapSample RunSample(const Scene& base, const SweepRun& run, const Reference& reference,
                    AsyncRegions& regions, double* adaptive_s, std::size_t* trials) {
  MapSample sample;
  sample.spectral_radius = kNaN;  // not estimated
  sample.reference_peak_n = reference.trial.peak_force_n;
  sample.l2_percent = sample.max_magnitude_percent = sample.max_direction_deg = kNaN;
  if (!reference.ok) {
    sample.status = SampleStatus::kDiverged;
    sample.status_region = kNoRegion;
    return sample;
  }
  const Scene scene = SceneAtPoint(base, run.point);
  const auto t1 = Clock::now();
  const TrialResult trial = regions.RunTrial(scene.input);
  *adaptive_s += SecondsSince(t1);
  ++*trials;
  const double simulated_ms = trial.steps * scene.solver.dt_s * 1e3;
  for (int r = 0; r < std::min(kMapCostRegions, regions.num_regions()); ++r) {
    sample.cost_us_per_ms[r] = regions.compute_seconds(r) * 1e6 / simulated_ms;
  }
  if (trial.outcome == TrialOutcome::kCompleted) {
    const ForceError error = CompareForces(trial.samples, reference.trial.samples);
    sample.status = SampleStatus::kOk;
    sample.l2_percent = error.l2_percent;
    sample.max_magnitude_percent = error.max_magnitude_percent;
    sample.max_direction_deg = error.max_direction_deg;
  } else {
    sample.status = SampleStatus::kDiverged;
    sample.status_region = static_cast<std::int8_t>(regions.LargestStateRegion());
  }
  return sample;
}

// Phase 2, one task: its regions built once, every run made, each sample placed where its
// targets say (another amplitude or density: the reference peak scaled).
PlacedSamples RunTask(const Scene& base, const SweepTask& task, const References& references,
                      const ErrorMap& map, SteppingOrder order, double* adaptive_s,
                      std::size_t* trials) {
  PlacedSamples results;
  // No stability estimate: the interface controllers hold most lagged exchanges, what their
  // dissipation costs is in the error this trial measures, and a trial that diverges anyway is
  // recorded as diverged (docs/regions.md, "Passive interfaces"). The runaway watch ends it too.
  AsyncRegions regions(SceneAtPoint(base, task.point));
  regions.SetSteppingOrder(order);
  for (const SweepRun& run : task.runs) {
    const MapSample sample =
        RunSample(base, run, references.at(ReferenceKeyOf(run.point)), regions, adaptive_s, trials);
    for (const SweepTarget& target : run.targets) {
      MapSample placed = sample;
      placed.point = map.samples[target.sample].point;
      placed.reference_peak_n = sample.reference_peak_n * target.scale;
      results.emplace_back(target.sample, placed);
    }
  }
  return results;
}

// This shard's task numbers, and what they hold, into `stats`.
std::vector<std::size_t> ShardTasks(const std::vector<SweepTask>& tasks,
                                    const SweepOptions& options, SweepStats* stats) {
  std::vector<std::size_t> mine;
  for (std::size_t t = options.shard_index; t < tasks.size(); t += options.shard_count) {
    mine.push_back(t);
  }
  stats->tasks = mine.size();
  for (std::size_t t : mine) {  // savings are counted for this shard's tasks only
    const SweepTask& task = tasks[t];
    for (const SweepRun& run : task.runs) stats->samples += run.targets.size();
    stats->saved_by_similarity += task.saved_by_similarity;
    stats->saved_by_linearity += task.saved_by_linearity;
    stats->saved_by_same_regions += task.saved_by_same_regions;
  }
  return mine;
}

}  // namespace

ModelTraits CurrentModel() {
  return {"linear hexahedral FEM (C3D8, lumped mass, C = d·M), central difference; regions v1",
          true, true};
}

std::string CodeVersion() { return HAPTICSIM_CODE_VERSION; }

ErrorMap RunSweep(const Scene& scene, const SweepGrid& grid, const SweepOptions& options,
                  SweepStats* stats_out) {
  // The map is of the regions' error under a pressed node: a scene for hapticsimd's sliding tool
  // (contact.model = "proxy") is swept with the node contact, its object and regions the same.
  Scene base = scene;
  base.contact.model = ContactModel::kNode;
  ValidateGrid(grid);
  HAPTICSIM_THROW_UNLESS(base.input.waveform != Waveform::kStroke,
                         "input.waveform = \"stroke\": an error map is swept over presses and "
                         "sines; set input.waveform = \"press\" (or \"sine\") for the sweep, and "
                         "compare a stroke with `hapticsim simulate`");
  HAPTICSIM_THROW_UNLESS(options.shard_count >= 1 && options.shard_index >= 0 &&
                             options.shard_index < options.shard_count,
                         "--shard I/N needs 1 ≤ I ≤ N");
  const auto start = Clock::now();
  SweepStats stats;
  const ModelTraits model = CurrentModel();
  const bool linear = options.use_linearity && model.linear && !grid.scattered;
  ErrorMap map = EmptyMap(base, grid, options, model, linear);
  const std::vector<SweepTask> all_tasks =
      grid.scattered
          ? PlanScatteredTasks(grid)
          : PlanGridTasks(base, grid, linear, options.use_similarity && model.similar_in_density);
  const std::vector<std::size_t> mine = ShardTasks(all_tasks, options, &stats);

  const std::string fingerprint = SweepFingerprint(map, grid, options);
  std::vector<bool> done(all_tasks.size(), false);
  if (options.resume && !options.journal_path.empty()) {
    done = ReadSweepJournal(options.journal_path, fingerprint, all_tasks.size(), &map);
  }
  SweepJournal journal(options.journal_path, fingerprint, options.resume);
  std::vector<std::size_t> todo;
  for (std::size_t t : mine) {
    if (done[t]) {
      for (const SweepRun& run : all_tasks[t].runs) stats.samples_resumed += run.targets.size();
    } else {
      todo.push_back(t);
    }
  }

  std::atomic<std::size_t> samples_done{stats.samples_resumed};
  auto tick = [&] {
    if (!options.progress) return;
    SweepProgress progress;
    progress.samples_done = samples_done.load();
    progress.samples_total = stats.samples;
    progress.samples_resumed = stats.samples_resumed;
    progress.elapsed_s = SecondsSince(start);
    options.progress(progress);
  };
  const References references = RunReferences(base, all_tasks, todo, options, tick, &stats);
  std::mutex journal_mutex;
  ParallelFor(
      todo.size(), options.jobs, options.stop,
      [&](std::size_t i) {
        double adaptive_s = 0;
        std::size_t trials = 0;
        const PlacedSamples results =
            RunTask(base, all_tasks[todo[i]], references, map, options.order, &adaptive_s, &trials);
        for (const auto& [index, sample] : results) {
          map.samples[index] = sample;  // each sample belongs to exactly one task
        }
        {
          std::lock_guard lock(journal_mutex);
          journal.Append(todo[i], results);
          stats.adaptive_trials += trials;
          stats.adaptive_seconds += adaptive_s;
        }
        samples_done += results.size();
      },
      tick, options.progress_interval_s);
  stats.interrupted = options.stop && options.stop->load() && samples_done.load() < stats.samples;
  stats.wall_seconds = SecondsSince(start);
  if (stats_out) *stats_out = stats;
  return map;
}

}  // namespace hapticsim
