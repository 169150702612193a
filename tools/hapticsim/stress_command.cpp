// hapticsim stress: the numerical-stability stress test. Random scenes and configurations are
// predicted and then run (core/regions/stability_stress.hpp); the supervisor is asked to choose for each
// scene, also from an error map that calls every configuration fine, and what it chose is run
// as the daemon runs it.
#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iostream>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <random>
#include <thread>
#include <tuple>

#include "core/regions/async_regions.hpp"
#include "core/error.hpp"
#include "core/errormap/error_map.hpp"
#include "core/scene/scene_toml.hpp"
#include "core/regions/stability_stress.hpp"
#include "daemon/supervisor.hpp"
#include "tools/hapticsim/command.hpp"
#include "tools/hapticsim/progress_line.hpp"

namespace hapticsim::cli {
namespace {

using Json = nlohmann::json;

struct StressOptions {
  int count = 1000;
  std::uint64_t seed = 1;
  int jobs = 0;
  int only_case = -1;
  std::string scene_out;
  int supervisor_every = 1;
  StressRanges ranges;
  bool faults = false;
  double fault_run_s = 1.0;
  bool json = false;
};

// What the supervisor did for one case's scene.
struct SupervisorCheck {
  int choices = 0;         // decisions made (without a map, from a lying map, pinned)
  int chose_unstable = 0;  // a chosen configuration that, run as the daemon runs it, broke the
                           // energy balance without the runaway watch ending it
  int stable_pinned_refused = 0;  // the scene's own configuration refused (pinned or no map)
  int runaways = 0;               // chosen runs the runaway watch ended (the daemon demotes them)
  std::string problem;
  double seconds = 0;  // wall time of the checks
};

// The supervisor no longer estimates stability (docs/regions.md, "Stable by construction"), so
// what it chose is run here as the daemon runs it: production substeps, interface controllers and
// runaway watch on, the regions stepped in the order hapticsimd's threads step them, from the
// case's random start under its input for 2 s. It must end within the energy balance the
// controllers guarantee (the same check as the case's own run), or be ended by the runaway watch —
// which the daemon answers by taking the regions to equal rates. Diverging any other way, or
// keeping more energy than the balance allows, is a failure ("" when none).
struct GuardedRun {
  bool runaway = false;
  std::string problem;
};
GuardedRun RunAsTheDaemonRunsIt(const Scene& scene, unsigned state_seed) {
  GuardedRun out;
  AsyncRegions regions(scene, AsyncRegions::kSubstepSafety);
  regions.SetSteppingOrder(SteppingOrder::kThreads);
  InputSettings input = scene.input;
  input.periods = 2.0 * input.frequency_hz;
  StressOutcome as_run;  // its energy_balance_violated() is the case's own check
  as_run.passive_expected = scene.adaptivity.displacement_coupling;
  const TrialResult trial = RunAsTheDaemonRuns(regions, input, state_seed, &as_run);
  if (trial.runaway) {
    out.runaway = true;
    return out;
  }
  if (trial.diverged()) {
    out.problem = "diverged without the runaway watch ending it";
  } else if (as_run.energy_balance_violated()) {
    out.problem = "ended " + std::to_string(as_run.energy_gain_j) +
                  " J above the interface controllers' energy bound";
  }
  return out;
}

// An error map for this scene's material and input that calls four configurations fine (two
// primary sizes × two secondary rates at the scene's spacing factor): what the supervisor chooses
// from it is run as the daemon runs it. Four, not the paper's 60, keeps a case's checks to a few
// runs.
ErrorMap LyingMap(const Scene& scene, std::mt19937_64& rng) {
  std::array<std::vector<double>, kNumMapAxes> axes;
  const MapPoint at = PointOfScene(scene);
  for (int a = 0; a < kNumMapAxes; ++a) axes[a] = {at[a]};  // material, input, contact node
  axes[static_cast<int>(MapAxis::kSecondaryLod)] = {
      static_cast<double>(scene.adaptivity.secondary_lod)};
  const int size = std::uniform_int_distribution<int>(1, 3)(rng);
  axes[static_cast<int>(MapAxis::kPrimarySize)] = {static_cast<double>(size),
                                                   static_cast<double>(size + 1)};
  const double primary = std::round(1.0 / scene.solver.dt_s);
  const int percent = std::uniform_int_distribution<int>(5, 9)(rng) * 10;
  axes[static_cast<int>(MapAxis::kSecondaryRate)] = {primary * percent / 100, primary};
  ErrorMap map = ErrorMap::MakeGrid(axes);
  std::uniform_real_distribution<double> error(0, 10), cost(10, 500);
  for (MapSample& sample : map.samples) {
    sample.status = SampleStatus::kOk;
    sample.l2_percent = sample.max_magnitude_percent = error(rng);
    sample.max_direction_deg = 1;
    sample.reference_peak_n = 1;
    sample.cost_us_per_ms[0] = cost(rng);
  }
  return map;
}

SupervisorCheck CheckSupervisor(const StressOutcome& outcome) {
  const auto start = std::chrono::steady_clock::now();
  SupervisorCheck check;
  const Scene& scene = outcome.stress_case.scene;
  std::mt19937_64 rng(outcome.stress_case.state_seed);
  const ErrorMap lying = LyingMap(scene, rng);
  // Each chosen configuration run once.
  std::map<std::tuple<int, int, double, double>, GuardedRun> runs;
  auto run = [&](const RegionConfiguration& c) -> const GuardedRun& {
    const auto key =
        std::make_tuple(c.primary_size, c.secondary_lod, c.secondary_rate_hz, c.outer_rate_hz);
    const auto found = runs.find(key);
    if (found != runs.end()) return found->second;
    GuardedRun& ran = runs[key] =
        RunAsTheDaemonRunsIt(SceneWith(scene, c), outcome.stress_case.state_seed);
    if (ran.runaway) {
      // The daemon then runs every secondary at the primary rate there: that must hold.
      ++check.runaways;
      const GuardedRun then = RunAsTheDaemonRunsIt(SceneWith(scene, AtEqualRates(scene, c)),
                                                   outcome.stress_case.state_seed);
      if (then.runaway) ran.problem = "ran away, and again at equal rates";
      if (!then.problem.empty()) ran.problem = "ran away; at equal rates it " + then.problem;
    }
    return ran;
  };
  auto verify = [&](const char* how, const ErrorMap* map,
                    const std::optional<RegionConfiguration>& pinned) {
    ++check.choices;
    std::optional<SupervisorDecision> decision;
    try {
      decision = ChooseConfiguration(scene, map, 5.0, pinned);
    } catch (const Error& e) {
      // Regions that cannot be built are the only refusal, and the scene's own always build (a
      // lying map's four may all fail to on a small mesh: that refusal is right).
      if (map == nullptr) {
        ++check.stable_pinned_refused;
        check.problem = std::string(how) + " refused: " + e.what();
      }
      return;
    }
    if (const GuardedRun& ran = run(decision->configuration); !ran.problem.empty()) {
      ++check.chose_unstable;
      check.problem = std::string(how) + " chose " + decision->reason + ", which " + ran.problem;
    }
  };
  const RegionConfiguration own{scene.adaptivity.primary_size, scene.adaptivity.secondary_lod,
                                scene.adaptivity.secondary_rate_hz};
  verify("pinned to the scene's own configuration", nullptr, own);
  verify("without a map", nullptr, std::nullopt);
  verify("from a map calling four configurations fine", &lying, std::nullopt);
  check.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return check;
}

Json CaseJson(const StressOutcome& o) {
  return {
      {"index", o.stress_case.index},
      {"description", DescribeStressCase(o.stress_case)},
      {"step_over_limit", o.step_over_limit},
      {"spectral_radius", std::isfinite(o.spectral_radius) ? Json(o.spectral_radius) : Json("inf")},
      {"energy_gain_j", o.energy_gain_j},
      {"energy_scale_j", o.energy_scale_j},
      {"backlog_bound_j", o.backlog_bound_j},
      {"controlled_outcome", std::string(TrialOutcomeName(o.controlled_outcome))},
      {"predicted_stable", o.predicted_stable},
      {"bound_periods", o.bound_periods},
      {"outcome", std::string(TrialOutcomeName(o.outcome))},
      {"periods_run", o.periods_run},
      {"diverged_region", o.diverged_region}};
}

// --scene-out: case I's scene as a scene file, to run it in the daemon or `simulate`.
int WriteCaseScene(const StressOptions& o) {
  HAPTICSIM_THROW_UNLESS(o.only_case >= 0, "--scene-out needs --case I: the case to write");
  const StressCase c = DrawStressCase(o.seed, o.only_case, o.ranges);
  std::ofstream out(o.scene_out);
  out << "# hapticsim stress --seed " << o.seed << " --min-nodes " << o.ranges.min_nodes
      << " --max-nodes " << o.ranges.max_nodes << " --case " << o.only_case << "\n# "
      << DescribeStressCase(c) << "\n"
      << FormatSceneToml(c.scene);
  out.close();
  HAPTICSIM_THROW_UNLESS(out, "cannot write " + o.scene_out + ": " + std::strerror(errno));
  std::cerr << "case " << o.only_case << "'s scene written to " << o.scene_out
            << (c.substep_safety > AsyncRegions::kSubstepSafety
                    ? " (the case steps one region near its own limit; hapticsimd and simulate "
                      "build it with production substeps)"
                    : "")
            << "\n";
  return 0;
}

int Run(const StressOptions& o) {
  if (!o.scene_out.empty()) return WriteCaseScene(o);
  HAPTICSIM_THROW_UNLESS(o.count >= 1, "--count must be at least 1");
  HAPTICSIM_THROW_UNLESS(o.ranges.min_nodes >= 3 && o.ranges.max_nodes >= o.ranges.min_nodes,
                         "--nodes MIN MAX: need 3 <= MIN <= MAX");
  const int first = o.only_case >= 0 ? o.only_case : 0;
  const int count = o.only_case >= 0 ? 1 : o.count;
  const int jobs =
      std::max(1, std::min(count, o.jobs > 0 ? o.jobs
                                             : static_cast<int>(std::max(
                                                   1u, std::thread::hardware_concurrency()))));
  std::vector<StressOutcome> outcomes(static_cast<size_t>(count));
  std::vector<SupervisorCheck> checks(static_cast<size_t>(count));
  std::vector<FaultOutcome> fault_outcomes(static_cast<size_t>(count));
  std::atomic<int> next{0}, done{0};
  std::mutex error_mutex;
  std::string first_error;
  const auto start = std::chrono::steady_clock::now();
  auto worker = [&] {
    for (int i; (i = next++) < count;) {
      try {
        const StressCase c = DrawStressCase(o.seed, first + i, o.ranges);
        outcomes[i] = RunStressCase(c, o.ranges);
        if ((first + i) % o.supervisor_every == 0) checks[i] = CheckSupervisor(outcomes[i]);
        if (o.faults) {
          fault_outcomes[i] =
              RunFaultCase(outcomes[i], o.fault_run_s, StressTimingFaults(c.state_seed));
        }
      } catch (const std::exception& e) {
        std::lock_guard lock(error_mutex);
        if (first_error.empty())
          first_error = "case " + std::to_string(first + i) + ": " + e.what();
      }
      ++done;
    }
  };
  std::vector<std::thread> threads;
  for (int j = 0; j < jobs; ++j) threads.emplace_back(worker);
  ProgressLine progress("stress", 10.0, "cases");
  auto elapsed = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  while (done < count) {
    progress.Update(static_cast<size_t>(done.load()), static_cast<size_t>(count),
                    static_cast<size_t>(done.load()), elapsed());
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }
  for (auto& thread : threads) thread.join();
  progress.Update(static_cast<size_t>(count), static_cast<size_t>(count),
                  static_cast<size_t>(count), elapsed());
  progress.Finish();
  HAPTICSIM_THROW_UNLESS(first_error.empty(), first_error);

  long predicted_stable = 0, stable_diverged = 0, past_limit = 0, coupling_only = 0, unstable = 0,
       detected = 0, undetected = 0, marginal = 0, marginal_detected = 0, region_is_past_limit = 0,
       past_limit_diverged = 0, choices = 0, chose_unstable = 0, pinned_refused = 0, runaways = 0,
       energy_violations = 0, passive = 0, passive_refused_today = 0, passive_diverged = 0,
       other_controlled = 0, other_controlled_diverged = 0;
  double worst_energy_gain = -INFINITY;  // relative to the case's energy scale
  double worst_detection_fraction = 0, slowest_case_s = 0, cases_s = 0, supervisor_s = 0;
  long fault_runs = 0, fault_diverged = 0, fault_violations = 0;
  FaultCounts injected;
  double max_force_step = 0, max_step_nominal = 0, worst_fault_gain = -INFINITY;
  int max_step_case = -1;
  Json failures = Json::array();
  Json fault_violating = Json::array();
  Json fault_above_tolerance = Json::array();  // reported, not checked (docs/reliability.md)
  long fault_above = 0;
  for (int i = 0; i < count; ++i) {
    const StressOutcome& out = outcomes[i];
    const SupervisorCheck& check = checks[i];
    slowest_case_s = std::max(slowest_case_s, out.seconds + check.seconds);
    cases_s += out.seconds;
    supervisor_s += check.seconds;
    choices += check.choices;
    chose_unstable += check.chose_unstable;
    pinned_refused += check.stable_pinned_refused;
    runaways += check.runaways;
    if (out.energy_balance_violated()) ++energy_violations;
    const FaultOutcome& fault = fault_outcomes[i];
    if (fault.ran) {
      ++fault_runs;
      if (fault.diverged) ++fault_diverged;
      if (fault.energy_balance_violated()) {
        ++fault_violations;
        fault_violating.push_back({{"index", out.stress_case.index},
                                   {"energy_gain_j", fault.energy_gain_j},
                                   {"backlog_bound_j", fault.backlog_bound_j},
                                   {"energy_scale_j", fault.energy_scale_j},
                                   {"description", DescribeStressCase(out.stress_case)}});
      }
      if (fault.above_backlog_tolerance()) {
        ++fault_above;
        fault_above_tolerance.push_back({{"index", out.stress_case.index},
                                         {"energy_gain_j", fault.energy_gain_j},
                                         {"energy_scale_j", fault.energy_scale_j},
                                         {"description", DescribeStressCase(out.stress_case)}});
      }
      worst_fault_gain = std::max(worst_fault_gain, fault.energy_gain_j / fault.energy_scale_j);
      injected += fault.faults;
      if (!fault.diverged && fault.max_force_step_n > max_force_step) {
        max_force_step = fault.max_force_step_n;
        max_step_nominal = fault.nominal_force_step_n;
        max_step_case = out.stress_case.index;
      }
    }
    if ((out.predicted_stable || out.passive_expected) && out.energy_scale_j > 0) {
      worst_energy_gain = std::max(worst_energy_gain, out.energy_gain_j / out.energy_scale_j);
    }
    if (out.passive_expected) {
      ++passive;
      if (!out.predicted_stable) ++passive_refused_today;
      if (out.passive_but_diverged()) ++passive_diverged;
    } else if (out.controlled_run) {
      ++other_controlled;
      if (out.controlled_diverged()) ++other_controlled_diverged;
    }
    if (out.predicted_stable) {
      ++predicted_stable;
      if (out.stable_but_diverged()) ++stable_diverged;  // bare or as run
    } else {
      ++unstable;
      if (out.past_limit) ++past_limit;
      if (out.coupling_only_unstable) ++coupling_only;
      if (out.marginal) {
        ++marginal;
        if (out.diverged()) ++marginal_detected;
      } else if (out.diverged()) {
        ++detected;
        worst_detection_fraction = std::max(
            worst_detection_fraction, static_cast<double>(out.periods_run) / out.bound_periods);
      } else {
        ++undetected;
      }
      if (out.past_limit && out.diverged()) {
        ++past_limit_diverged;
        if (out.step_over_limit[static_cast<size_t>(out.diverged_region)] >= 1) {
          ++region_is_past_limit;
        }
      }
    }
    if (out.stable_but_diverged() || out.divergence_undetected() || out.passive_but_diverged() ||
        out.energy_balance_violated() || check.chose_unstable || check.stable_pinned_refused ||
        fault.diverged || fault.energy_balance_violated()) {
      Json entry = CaseJson(out);
      if (!check.problem.empty()) entry["supervisor"] = check.problem;
      if (fault.ran) {
        entry["under_faults"] = {{"outcome", std::string(TrialOutcomeName(fault.outcome))},
                                 {"diverged", fault.diverged},
                                 {"energy_gain_j", fault.energy_gain_j},
                                 {"backlog_bound_j", fault.backlog_bound_j},
                                 {"energy_scale_j", fault.energy_scale_j}};
      }
      failures.push_back(entry);
    }
  }
  const bool passed = stable_diverged == 0 && undetected == 0 && energy_violations == 0 &&
                      passive_diverged == 0 && fault_diverged == 0 && fault_violations == 0 &&
                      chose_unstable == 0 && pinned_refused == 0;
  const double seconds = elapsed();
  if (o.json) {
    Json out = {{"count", count},
                {"seed", o.seed},
                {"predicted_stable", predicted_stable},
                {"predicted_stable_diverged", stable_diverged},
                {"energy_balance_violations", energy_violations},
                {"worst_energy_gain_fraction", worst_energy_gain},
                {"passive_expected", passive},
                {"passive_expected_bare_unstable", passive_refused_today},
                {"passive_expected_diverged", passive_diverged},
                {"other_controlled_runs", other_controlled},
                {"other_controlled_diverged", other_controlled_diverged},
                {"predicted_unstable", unstable},
                {"run_past_limit", past_limit},
                {"coupling_only_unstable", coupling_only},
                {"divergence_detected", detected},
                {"divergence_undetected", undetected},
                {"marginal", marginal},
                {"marginal_detected", marginal_detected},
                {"worst_detection_fraction_of_bound", worst_detection_fraction},
                {"past_limit_diverged", past_limit_diverged},
                {"diverged_region_past_its_limit", region_is_past_limit},
                {"supervisor_choices", choices},
                {"supervisor_chose_unstable", chose_unstable},
                {"supervisor_refused_stable_pinned", pinned_refused},
                {"supervisor_runaways", runaways},
                {"seconds", seconds},
                {"slowest_case_s", slowest_case_s},
                {"prediction_and_run_s", cases_s},
                {"supervisor_checks_s", supervisor_s},
                {"passed", passed},
                {"failures", failures}};
    if (o.faults) {
      out["fault_runs"] = fault_runs;
      out["diverged_under_faults"] = fault_diverged;
      out["fault_energy_balance_violations"] = fault_violations;
      out["fault_energy_balance_violating_cases"] = fault_violating;
      out["fault_runs_above_backlog_tolerance"] = fault_above;
      out["fault_runs_above_backlog_tolerance_cases"] = fault_above_tolerance;
      out["worst_fault_energy_gain_fraction"] = worst_fault_gain;
      out["max_force_step_n"] = max_force_step;
      out["max_force_step_case"] = max_step_case;
      out["max_force_step_without_faults_n"] = max_step_nominal;
      out["faults_injected"] = {{"secondary_lags", injected.secondary_lags},
                                {"secondary_stalls", injected.secondary_stalls},
                                {"primary_late_wakes", injected.primary_late_wakes},
                                {"secondary_skips", injected.skips}};
      out["fault_run_s"] = o.fault_run_s;
    }
    if (o.only_case >= 0) out["case"] = CaseJson(outcomes[0]);
    std::cout << out.dump(2) << "\n";
  } else {
    if (o.only_case >= 0) {
      const StressOutcome& out = outcomes[0];
      std::cout << DescribeStressCase(out.stress_case) << "\n  step / own limit per region:";
      for (double r : out.step_over_limit) std::cout << " " << r;
      std::cout << "\n  coupled spectral radius " << out.spectral_radius << " per "
                << out.common_period_s * 1e3 << " ms; predicted "
                << (out.predicted_stable ? "stable" : "unstable")
                << "\n  run: " << TrialOutcomeName(out.outcome) << " after " << out.periods_run
                << " periods"
                << (out.diverged() ? " (region " + std::to_string(out.diverged_region) + ")" : "")
                << (out.predicted_stable ? "" : ", bound " + std::to_string(out.bound_periods))
                << "\n";
    }
    std::cout
        << "stress: " << count << " cases (seed " << o.seed << ") in " << seconds
        << " s (CPU: predictions and runs " << cases_s << " s, supervisor checks " << supervisor_s
        << " s; slowest case " << slowest_case_s << " s)\n"
        << "  predicted stable            " << predicted_stable << ", of which diverged "
        << stable_diverged << "\n"
        << "  energy bound                " << energy_violations
        << " cases above it by more than allowed (the port limits' backlog; 1 % where held by "
           "the controllers; one step where predicted stable. Worst: above the controllers' "
           "bound by "
        << worst_energy_gain << " of the case's energy)\n"
        << "  held by the controllers     " << passive
        << " (production margin, displacement exchange; bare exchange unstable "
        << passive_refused_today << "), of which diverged as run " << passive_diverged << "\n"
        << "  other runs as the daemon    " << other_controlled
        << " (near a region's limit or the force exchange: not guaranteed), diverged "
        << other_controlled_diverged << "\n"
        << "  predicted unstable          " << unstable << " (a region past its own limit "
        << past_limit << ", only the coupling " << coupling_only << ")\n"
        << "    divergence detected       " << detected << " (at most "
        << worst_detection_fraction * 100 << " % of the predicted bound)\n"
        << "    divergence undetected     " << undetected << "\n"
        << "    too slow to detect        " << marginal << " (detected anyway " << marginal_detected
        << ")\n"
        << "    region reported is past its limit: " << region_is_past_limit << " of "
        << past_limit_diverged << "\n"
        << "  supervisor decisions        " << choices
        << ", run as the daemon runs them (its threads' order): " << chose_unstable
        << " broke the energy balance unguarded, " << runaways
        << " ended by the runaway watch (the daemon takes those to equal rates); pinned "
           "refused "
        << pinned_refused << "\n";
    if (o.faults) {
      std::cout << "  under timing faults         " << fault_runs << " runs of " << o.fault_run_s
                << " s on real threads (" << injected.secondary_lags << " secondary lags, "
                << injected.secondary_stalls << " stalls, " << injected.primary_late_wakes
                << " late primary wakes, " << injected.skips << " skips), diverged "
                << fault_diverged << ", above the energy bound by more than the port limits allow "
                << fault_violations << " (where they act), by more than 1 % without them "
                << fault_above << " (reported, not checked)\n    largest force step "
                << max_force_step << " N (case " << max_step_case << "; " << max_step_nominal
                << " N on the nominal schedule)\n";
    }
    for (const Json& failure : failures) std::cout << "FAILED " << failure.dump() << "\n";
    std::cout << (passed ? "passed\n" : "FAILED\n");
  }
  return passed ? kExitOk : kExitLimitsExceeded;
}

}  // namespace

Command AddStressCommand(CLI::App& parent) {
  auto options = std::make_shared<StressOptions>();
  CLI::App* app = parent.add_subcommand(
      "stress",
      "Numerical-stability stress test: random scenes and configurations (materials beyond the "
      "paper's ranges, meshes, primary sizes, spacing factors, rates, coupling, steps around each "
      "region's own limit, extreme inputs) predicted, then run from a random state; checks that "
      "every predicted-stable one stays bounded, every unstable one is detected within its "
      "predicted bound, and what the supervisor chooses keeps the energy balance as the daemon "
      "runs "
      "it, or is caught by the runaway watch. Exit 4 when a check "
      "fails.");
  app->add_option("--count", options->count, "Number of random cases")->capture_default_str();
  app->add_option("--seed", options->seed, "Seed of the draw (case i is the same for any --jobs)")
      ->capture_default_str();
  app->add_option("--jobs", options->jobs, "Worker threads (0: one per core)")
      ->capture_default_str();
  app->add_option("--case", options->only_case,
                  "Run only case I of the seed and describe it (to reproduce a failure)");
  app->add_option("--scene-out", options->scene_out,
                  "With --case I: write case I's scene to this TOML file and exit (to run it in "
                  "hapticsimd or `hapticsim simulate`)");
  app->add_option("--min-nodes", options->ranges.min_nodes, "Smallest mesh, nodes per axis")
      ->capture_default_str();
  app->add_option("--max-nodes", options->ranges.max_nodes, "Largest mesh, nodes per axis")
      ->capture_default_str();
  app->add_option("--stable-run", options->ranges.stable_run_s,
                  "Simulated time of a predicted-stable run, s")
      ->capture_default_str();
  app->add_option("--max-run", options->ranges.max_run_s,
                  "Longest simulated time of a predicted-unstable run, s")
      ->capture_default_str();
  app->add_option("--supervisor-every", options->supervisor_every,
                  "Ask the supervisor to choose for every Nth case only (each choice is run as "
                  "the daemon runs it, in its threads' order, 2 s of simulated time)")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app->add_flag("--faults", options->faults,
                "Also run every case the daemon would run (or the controllers should hold) on real "
                "threads with injected timing faults: secondary lags of 1-10 periods, stalls up to "
                "0.3 s, late primary wakes; counts divergence and energy-bound violations");
  app->add_option("--fault-run", options->fault_run_s, "Wall time of each run under faults, s")
      ->capture_default_str()
      ->check(CLI::Range(0.05, 60.0));
  app->add_flag("--json", options->json, "One JSON object on stdout");
  return {app, [options] { return Run(*options); }};
}

}  // namespace hapticsim::cli
