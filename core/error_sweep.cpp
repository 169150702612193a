#include "core/error_sweep.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstring>
#include <exception>
#include <fstream>
#include <limits>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "core/async_regions.hpp"
#include "core/cube_scene.hpp"
#include "core/error.hpp"
#include "core/fnv1a.hpp"
#include "core/force_error.hpp"
#include "core/reference_trial.hpp"
#include "core/region_partition.hpp"
#include "core/scene_toml.hpp"

#ifndef HAPTICSIM_CODE_VERSION
#define HAPTICSIM_CODE_VERSION "unknown"
#endif

namespace hapticsim {
namespace {

using Json = nlohmann::json;
using Clock = std::chrono::steady_clock;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

constexpr int Axis(MapAxis axis) { return static_cast<int>(axis); }

// The material and input (with the contact node) a reference depends on.
using ReferenceKey = std::array<double, 9>;
ReferenceKey ReferenceKeyOf(const MapPoint& p) {
  return {p[Axis(MapAxis::kPoissonRatio)], p[Axis(MapAxis::kDensity)],
          p[Axis(MapAxis::kDamping)],      p[Axis(MapAxis::kYoungsModulus)],
          p[Axis(MapAxis::kAmplitude)],    p[Axis(MapAxis::kFrequency)],
          p[Axis(MapAxis::kContactNodeX)], p[Axis(MapAxis::kContactNodeY)],
          p[Axis(MapAxis::kContactNodeZ)]};
}

struct Reference {
  MapPoint point{};  // a run that needs it: its configuration axes are not used
  TrialResult trial;
  bool ok = false;
};

// A sample a run fills: its forces are `scale` × the run's (another amplitude, by linearity;
// another density at the same E/ρ, by similarity).
struct Target {
  std::size_t sample = 0;
  double scale = 1;
};

// One adaptive run (one input) and the samples it answers.
struct Run {
  MapPoint point{};  // where the run is made (its amplitude is the run's)
  std::vector<Target> targets;
};

// One material and one configuration: regions built and stability estimated once.
struct Task {
  MapPoint point{};  // material + configuration (+ the first run's input)
  std::vector<Run> runs;
  // Adaptive runs this task's runs stand for but not make, by saving (a shard sums its own).
  std::size_t saved_by_similarity = 0, saved_by_linearity = 0, saved_by_same_regions = 0;
};

// Identifies the regions a configuration produces: per region its element and node counts.
// Primary boxes around the same contact are nested, so equal counts mean equal regions.
std::vector<int> RegionSignature(const Scene& scene) {
  const RegionPartition partition(scene);
  std::vector<int> signature;
  for (int r = 0; r < partition.num_regions(); ++r) {
    signature.push_back(partition.num_elements(r));
    signature.push_back(partition.num_nodes(r));
  }
  return signature;
}

// The grid's materials (the four material axes, the last fastest) and, per material, the one
// that is run for it: the first of equal E/ρ, ν and d when `similar`, else itself.
struct GridMaterials {
  std::vector<std::array<int, 4>> index;  // per material: its index on each material axis
  std::vector<std::size_t> run_as;
};
GridMaterials MaterialsOf(const std::array<std::vector<double>, kNumMapAxes>& ax, bool similar) {
  const int nu = Axis(MapAxis::kPoissonRatio), rho = Axis(MapAxis::kDensity),
            d = Axis(MapAxis::kDamping), e = Axis(MapAxis::kYoungsModulus);
  static_assert(Axis(MapAxis::kPoissonRatio) == 0 && Axis(MapAxis::kYoungsModulus) == 3,
                "the material axes are the first four");
  GridMaterials out;
  const size_t count = ax[0].size() * ax[1].size() * ax[2].size() * ax[3].size();
  for (size_t m = 0; m < count; ++m) {
    std::array<int, 4> index{};
    for (int a = 3, rest = static_cast<int>(m); a >= 0; --a) {
      index[a] = rest % static_cast<int>(ax[a].size());
      rest /= static_cast<int>(ax[a].size());
    }
    out.index.push_back(index);
    out.run_as.push_back(m);
    if (!similar) continue;
    const double wave_speed_squared = ax[e][index[e]] / ax[rho][index[rho]];
    for (size_t earlier = 0; earlier < m; ++earlier) {
      if (out.run_as[earlier] != earlier) continue;  // only a material that is run answers
      const std::array<int, 4>& o = out.index[earlier];
      if (o[nu] == index[nu] && o[d] == index[d] &&
          std::abs(ax[e][o[e]] / ax[rho][o[rho]] - wave_speed_squared) <=
              1e-12 * wave_speed_squared) {
        out.run_as.back() = earlier;
        break;
      }
    }
  }
  return out;
}

std::vector<Task> GridTasks(const Scene& base, const SweepGrid& grid, bool linear, bool similar) {
  const auto& ax = grid.axes;
  const ErrorMap layout = ErrorMap::MakeGrid(ax);
  const int lod_axis = Axis(MapAxis::kSecondaryLod), size_axis = Axis(MapAxis::kPrimarySize);
  constexpr std::array<int, 3> kContactAxes = {static_cast<int>(MapAxis::kContactNodeX),
                                               static_cast<int>(MapAxis::kContactNodeY),
                                               static_cast<int>(MapAxis::kContactNodeZ)};
  std::size_t contacts = 1;
  for (int a : kContactAxes) contacts *= ax[a].size();
  // The contact node's axis indices, the last axis fastest.
  auto contact_index = [&](std::size_t c, std::array<int, kNumMapAxes>* index) {
    for (int k = 2; k >= 0; --k) {
      const int a = kContactAxes[k];
      (*index)[a] = static_cast<int>(c % ax[a].size());
      c /= ax[a].size();
    }
  };
  // Sizes that give the same regions, per contact node and spacing factor: run once, copied to
  // the others. (Boxes near an edge of the object are cut by it, so this depends on the node.)
  std::vector<std::vector<std::vector<std::vector<int>>>> size_groups(contacts);
  for (std::size_t c = 0; c < contacts; ++c) {
    size_groups[c].resize(ax[lod_axis].size());
    std::array<int, kNumMapAxes> index{};
    contact_index(c, &index);
    MapPoint at_node = layout.samples.front().point;
    for (int a : kContactAxes) at_node[a] = ax[a][index[a]];
    // A node that cannot be pressed is the grid's mistake, not the configuration's: said so.
    const LatticeIndex node = *SceneAtPoint(base, at_node).input.contact_node;
    const std::string problem = ContactNodeProblem(base.mesh, node);
    HAPTICSIM_THROW_UNLESS(problem.empty(), "the grid's contact node (contact_node_x, _y, _z) = (" +
                                                std::to_string(node[0]) + ", " +
                                                std::to_string(node[1]) + ", " +
                                                std::to_string(node[2]) + ") " + problem);
    for (size_t l = 0; l < ax[lod_axis].size(); ++l) {
      std::map<std::vector<int>, size_t> seen;
      for (size_t s = 0; s < ax[size_axis].size(); ++s) {
        MapPoint point = at_node;
        point[lod_axis] = ax[lod_axis][l];
        point[size_axis] = ax[size_axis][s];
        std::vector<int> signature;
        try {
          signature = RegionSignature(SceneAtPoint(base, point));
        } catch (const Error& e) {
          throw Error("configuration secondary_lod = " + FormatReal(point[lod_axis]) +
                      ", primary_size = " + FormatReal(point[size_axis]) + " at contact node (" +
                      FormatReal(point[kContactAxes[0]]) + ", " +
                      FormatReal(point[kContactAxes[1]]) + ", " +
                      FormatReal(point[kContactAxes[2]]) + "): " + e.what());
        }
        const auto [it, inserted] = seen.emplace(signature, size_groups[c][l].size());
        if (inserted) size_groups[c][l].emplace_back();
        size_groups[c][l][it->second].push_back(static_cast<int>(s));
      }
    }
  }
  const size_t amps = ax[Axis(MapAxis::kAmplitude)].size();
  const size_t freqs = ax[Axis(MapAxis::kFrequency)].size();
  std::vector<Task> tasks;
  std::array<int, kNumMapAxes> index{};
  auto point_at = [&](const std::array<int, kNumMapAxes>& i) {
    MapPoint p;
    for (int a = 0; a < kNumMapAxes; ++a) p[a] = ax[a][i[a]];
    return p;
  };
  // Materials outermost, then contact node, spacing factor, rate and region group: the order is
  // the task numbering that shards and journals use. A material run as an earlier one has no
  // tasks: the earlier one's runs fill its samples too.
  const GridMaterials materials = MaterialsOf(ax, similar);
  const int density = Axis(MapAxis::kDensity);
  for (size_t m = 0; m < materials.index.size(); ++m) {
    if (materials.run_as[m] != m) continue;
    std::vector<size_t> answered;  // the materials this one's runs answer: itself first
    for (size_t other = m; other < materials.index.size(); ++other) {
      if (materials.run_as[other] == m) answered.push_back(other);
    }
    for (int a = 0; a < 4; ++a) index[a] = materials.index[m][a];
    for (std::size_t c = 0; c < contacts; ++c) {
      contact_index(c, &index);
      for (size_t l = 0; l < ax[lod_axis].size(); ++l) {
        for (size_t r = 0; r < ax[Axis(MapAxis::kSecondaryRate)].size(); ++r) {
          for (const std::vector<int>& group : size_groups[c][l]) {
            Task task;
            index[lod_axis] = static_cast<int>(l);
            index[Axis(MapAxis::kSecondaryRate)] = static_cast<int>(r);
            index[size_axis] = group.front();
            for (size_t f = 0; f < freqs; ++f) {
              index[Axis(MapAxis::kFrequency)] = static_cast<int>(f);
              const size_t run_amps = linear ? 1 : amps;
              for (size_t ra = 0; ra < run_amps; ++ra) {
                Run run;
                index[Axis(MapAxis::kAmplitude)] = static_cast<int>(ra);
                index[size_axis] = group.front();
                run.point = point_at(index);
                const double amplitude = run.point[Axis(MapAxis::kAmplitude)];
                for (size_t member : answered) {
                  auto target_index = index;
                  for (int a = 0; a < 4; ++a) target_index[a] = materials.index[member][a];
                  const double density_ratio =
                      ax[density][target_index[density]] / ax[density][index[density]];
                  for (int s : group) {
                    for (size_t a = 0; a < amps; ++a) {
                      if (!linear && a != ra) continue;
                      target_index[size_axis] = s;
                      target_index[Axis(MapAxis::kAmplitude)] = static_cast<int>(a);
                      run.targets.push_back(
                          {layout.GridIndex(target_index),
                           ax[Axis(MapAxis::kAmplitude)][a] / amplitude * density_ratio});
                    }
                  }
                }
                // Counted in this order: similarity, then linearity, then same regions.
                task.saved_by_similarity +=
                    (answered.size() - 1) * (linear ? amps : 1) * group.size();
                task.saved_by_linearity += linear ? (amps - 1) * group.size() : 0;
                task.saved_by_same_regions += group.size() - 1;
                task.runs.push_back(std::move(run));
              }
            }
            task.point = task.runs.front().point;
            tasks.push_back(std::move(task));
          }
        }
      }
    }
  }
  return tasks;
}

std::vector<Task> ScatteredTasks(const SweepGrid& grid) {
  std::vector<Task> tasks;
  for (size_t i = 0; i < grid.points.size(); ++i) {
    Task task;
    task.point = grid.points[i];
    task.runs.push_back({grid.points[i], {{i, 1.0}}});
    tasks.push_back(std::move(task));
  }
  return tasks;
}

// Runs fn(i) for i in [0, n) on `jobs` threads; the calling thread reports progress meanwhile.
// The first exception stops the others and is rethrown.
void ParallelFor(std::size_t n, int jobs, const std::atomic<bool>* stop,
                 const std::function<void(std::size_t)>& fn, const std::function<void()>& tick,
                 double tick_interval_s) {
  std::atomic<std::size_t> next{0};
  std::atomic<bool> failed{false};
  std::exception_ptr error;
  std::mutex mutex;
  std::condition_variable done_cv;
  int running = std::max(1, jobs);
  std::vector<std::thread> workers;
  for (int j = 0; j < std::max(1, jobs); ++j) {
    workers.emplace_back([&] {
      for (;;) {
        if (failed || (stop && stop->load())) break;
        const std::size_t i = next.fetch_add(1);
        if (i >= n) break;
        try {
          fn(i);
        } catch (...) {
          std::lock_guard lock(mutex);
          if (!error) error = std::current_exception();
          failed = true;
        }
      }
      std::lock_guard lock(mutex);
      --running;
      done_cv.notify_all();
    });
  }
  {
    std::unique_lock lock(mutex);
    while (running > 0) {
      done_cv.wait_for(lock, std::chrono::duration<double>(tick_interval_s));
      lock.unlock();
      if (tick) tick();
      lock.lock();
    }
  }
  for (auto& worker : workers) worker.join();
  if (error) std::rethrow_exception(error);
}

Json SampleRecord(std::size_t index, const MapSample& s) {
  auto num = [](double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); };
  Json record =
      Json::array({index, static_cast<int>(s.status), static_cast<int>(s.status_region),
                   num(s.l2_percent), num(s.max_magnitude_percent), num(s.max_direction_deg),
                   num(s.reference_peak_n), num(s.spectral_radius)});
  for (double c : s.cost_us_per_ms) record.push_back(num(c));
  return record;
}

void ReadSampleRecord(const Json& record, ErrorMap* map) {
  auto num = [](const Json& v) { return v.is_null() ? kNaN : v.get<double>(); };
  const auto index = record.at(0).get<std::size_t>();
  if (index >= map->samples.size()) throw Error("journal sample index out of range");
  MapSample& s = map->samples[index];
  s.status = static_cast<SampleStatus>(record.at(1).get<int>());
  s.status_region = static_cast<std::int8_t>(record.at(2).get<int>());
  s.l2_percent = num(record.at(3));
  s.max_magnitude_percent = num(record.at(4));
  s.max_direction_deg = num(record.at(5));
  s.reference_peak_n = num(record.at(6));
  s.spectral_radius = num(record.at(7));
  for (int c = 0; c < kMapCostRegions; ++c) s.cost_us_per_ms[c] = num(record.at(8 + c));
}

std::string Fingerprint(const ErrorMap& map, const SweepGrid& grid, const SweepOptions& options) {
  std::ostringstream text;
  text << map.provenance.scene_toml << map.provenance.model << map.provenance.code_version
       << grid.name << options.shard_index << '/' << options.shard_count << options.use_linearity
       << options.use_similarity;
  Fnv1a hash;
  const std::string words = text.str();
  hash.Bytes(words.data(), words.size());
  for (const MapSample& s : map.samples) {
    for (double v : s.point) {
      std::uint64_t bits;
      std::memcpy(&bits, &v, sizeof bits);
      hash.Word(bits);
    }
  }
  std::ostringstream hex;
  hex << std::hex << hash.value();
  return hex.str();
}

// Completed tasks from a journal of the same sweep. A torn last line (a crash mid-write) is
// ignored; anything else that does not fit is refused.
std::vector<bool> ReadJournal(const std::string& path, const std::string& fingerprint,
                              std::size_t num_tasks, ErrorMap* map) {
  std::vector<bool> done(num_tasks, false);
  std::ifstream in(path);
  if (!in) return done;
  std::string line;
  if (!std::getline(in, line)) return done;
  Json header;
  try {
    header = Json::parse(line);
  } catch (const Json::exception&) {
    throw Error("journal " + path + " is not a sweep journal; delete it or drop --resume");
  }
  if (header.value("fingerprint", "") != fingerprint) {
    throw Error("journal " + path +
                " belongs to another sweep (other grid, scene, shard or code version); delete "
                "it or drop --resume");
  }
  while (std::getline(in, line)) {
    Json entry;
    try {
      entry = Json::parse(line);
    } catch (const Json::exception&) {
      break;  // torn write
    }
    const auto task = entry.at("task").get<std::size_t>();
    if (task >= num_tasks) throw Error("journal " + path + " names task " + std::to_string(task));
    for (const Json& record : entry.at("samples")) ReadSampleRecord(record, map);
    done[task] = true;
  }
  return done;
}

}  // namespace

ModelTraits CurrentModel() {
  return {"linear hexahedral FEM (C3D8, lumped mass, C = d·M), central difference; regions v1",
          true, true};
}

std::string CodeVersion() { return HAPTICSIM_CODE_VERSION; }

ErrorMap RunSweep(const Scene& base, const SweepGrid& grid, const SweepOptions& options,
                  SweepStats* stats_out) {
  ValidateGrid(grid);
  HAPTICSIM_THROW_UNLESS(options.shard_count >= 1 && options.shard_index >= 0 &&
                             options.shard_index < options.shard_count,
                         "--shard I/N needs 1 ≤ I ≤ N");
  const auto start = Clock::now();
  SweepStats stats;
  const ModelTraits model = CurrentModel();
  const bool linear = options.use_linearity && model.linear && !grid.scattered;

  ErrorMap map;
  if (grid.scattered) {
    map.grid = false;
    map.samples.resize(grid.points.size());
    for (size_t i = 0; i < grid.points.size(); ++i) map.samples[i].point = grid.points[i];
  } else {
    map = ErrorMap::MakeGrid(grid.axes);
  }
  map.provenance.scene_toml = FormatSceneToml(base);
  map.provenance.model = model.name;
  map.provenance.code_version = CodeVersion();
  map.provenance.grid = grid.name;
  map.provenance.shard =
      std::to_string(options.shard_index + 1) + "/" + std::to_string(options.shard_count);
  map.provenance.direction_threshold = ForceError::kDirectionThreshold;
  map.provenance.linearity_used = linear;
  for (const MapSample& s : map.samples) SceneAtPoint(base, s.point);  // validates every point

  std::vector<Task> all_tasks =
      grid.scattered
          ? ScatteredTasks(grid)
          : GridTasks(base, grid, linear, options.use_similarity && model.similar_in_density);
  std::vector<std::size_t> mine;  // task numbers of this shard
  for (std::size_t t = options.shard_index; t < all_tasks.size(); t += options.shard_count) {
    mine.push_back(t);
  }
  stats.tasks = mine.size();
  for (std::size_t t : mine) {  // savings are counted for this shard's tasks only
    const Task& task = all_tasks[t];
    for (const Run& run : task.runs) stats.samples += run.targets.size();
    stats.saved_by_similarity += task.saved_by_similarity;
    stats.saved_by_linearity += task.saved_by_linearity;
    stats.saved_by_same_regions += task.saved_by_same_regions;
  }

  const std::string fingerprint = Fingerprint(map, grid, options);
  std::vector<bool> done(all_tasks.size(), false);
  if (options.resume && !options.journal_path.empty()) {
    done = ReadJournal(options.journal_path, fingerprint, all_tasks.size(), &map);
  }
  std::ofstream journal;
  if (!options.journal_path.empty()) {
    const bool append = options.resume && std::ifstream(options.journal_path).good();
    journal.open(options.journal_path, append ? std::ios::app : std::ios::trunc);
    HAPTICSIM_THROW_UNLESS(journal.good(), "cannot write the journal " + options.journal_path);
    if (!append) journal << Json{{"journal", 1}, {"fingerprint", fingerprint}}.dump() << "\n";
    journal.flush();
  }
  std::vector<std::size_t> todo;
  for (std::size_t t : mine) {
    if (done[t]) {
      for (const Run& run : all_tasks[t].runs) stats.samples_resumed += run.targets.size();
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
    progress.elapsed_s = std::chrono::duration<double>(Clock::now() - start).count();
    options.progress(progress);
  };

  // Phase 1: one reference per material and input that this shard's remaining tasks need.
  std::map<ReferenceKey, Reference> references;
  for (std::size_t t : todo) {
    for (const Run& run : all_tasks[t].runs)
      references[ReferenceKeyOf(run.point)].point = run.point;
  }
  std::size_t reference_uses = 0;
  for (std::size_t t : todo) reference_uses += all_tasks[t].runs.size();
  std::vector<std::pair<const ReferenceKey, Reference>*> reference_list;
  for (auto& entry : references) reference_list.push_back(&entry);
  std::mutex stats_mutex;
  // Time in a worker between two points: CPU time while the machine is not oversubscribed.
  auto seconds_since = [](Clock::time_point t0) {
    return std::chrono::duration<double>(Clock::now() - t0).count();
  };
  ParallelFor(
      reference_list.size(), options.jobs, options.stop,
      [&](std::size_t i) {
        Reference& reference = reference_list[i]->second;
        Scene scene = SceneAtPoint(base, reference.point);
        scene.adaptivity.primary_size = 0;
        TrialOptions trial_options;
        trial_options.substep_to_stability = true;
        const auto t0 = Clock::now();
        reference.trial = RunReferenceTrial(CubeScene(scene), trial_options);
        reference.ok = reference.trial.outcome == TrialOutcome::kCompleted;
        std::lock_guard lock(stats_mutex);
        stats.reference_seconds += seconds_since(t0);
      },
      tick, options.progress_interval_s);
  stats.reference_trials = references.size();
  stats.saved_by_reference_reuse = reference_uses - references.size();

  // Phase 2: the tasks.
  std::mutex journal_mutex;
  ParallelFor(
      todo.size(), options.jobs, options.stop,
      [&](std::size_t i) {
        const Task& task = all_tasks[todo[i]];
        std::vector<std::pair<std::size_t, MapSample>> results;
        // No stability estimate: the interface controllers hold most lagged exchanges, what their
        // dissipation costs is in the error this trial measures, and a trial that diverges anyway
        // is recorded as diverged (docs/regions.md, "Passive interfaces"). The daemon verifies a
        // configuration before it runs it.
        AsyncRegions regions(SceneAtPoint(base, task.point));
        double adaptive_s = 0;
        std::size_t trials = 0;
        for (const Run& run : task.runs) {
          const Reference& reference = references.at(ReferenceKeyOf(run.point));
          MapSample sample;
          sample.spectral_radius = kNaN;  // not estimated
          sample.reference_peak_n = reference.trial.peak_force_n;
          sample.l2_percent = sample.max_magnitude_percent = sample.max_direction_deg = kNaN;
          if (!reference.ok) {
            sample.status = SampleStatus::kDiverged;
            sample.status_region = kNoRegion;
          } else {
            const Scene scene = SceneAtPoint(base, run.point);
            const auto t1 = Clock::now();
            const TrialResult trial = regions.RunTrial(scene.input);
            adaptive_s += seconds_since(t1);
            ++trials;
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
          }
          for (const Target& target : run.targets) {
            MapSample placed = sample;
            placed.point = map.samples[target.sample].point;
            placed.reference_peak_n = sample.reference_peak_n * target.scale;
            results.emplace_back(target.sample, placed);
          }
        }
        Json entry = {{"task", todo[i]}, {"samples", Json::array()}};
        for (const auto& [index, sample] : results) {
          map.samples[index] = sample;  // each sample belongs to exactly one task
          entry["samples"].push_back(SampleRecord(index, sample));
        }
        {
          std::lock_guard lock(journal_mutex);
          if (journal.is_open()) {
            journal << entry.dump() << "\n";
            journal.flush();
          }
          stats.adaptive_trials += trials;
          stats.adaptive_seconds += adaptive_s;
        }
        samples_done += results.size();
      },
      tick, options.progress_interval_s);
  stats.interrupted = options.stop && options.stop->load() && samples_done.load() < stats.samples;
  stats.wall_seconds = std::chrono::duration<double>(Clock::now() - start).count();
  if (stats_out) *stats_out = stats;
  return map;
}

}  // namespace hapticsim
