#include "core/regions/stability_stress.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>
#include <sstream>

#include "core/regions/async_regions.hpp"
#include "core/error.hpp"
#include "core/regions/region_partition.hpp"

namespace hapticsim {
namespace {

// A case's random stream: a pure function of (seed, index), independent of any other case.
std::mt19937_64 CaseStream(std::uint64_t seed, int index) {
  std::seed_seq sequence{static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32),
                         static_cast<std::uint32_t>(index), 0x57e55u};
  return std::mt19937_64(sequence);
}

double Uniform(std::mt19937_64& rng, double lo, double hi) {
  return std::uniform_real_distribution<double>(lo, hi)(rng);
}
double LogUniform(std::mt19937_64& rng, double lo, double hi) {
  return std::exp(Uniform(rng, std::log(lo), std::log(hi)));
}
int UniformInt(std::mt19937_64& rng, int lo, int hi) {
  return std::uniform_int_distribution<int>(lo, hi)(rng);
}
template <typename T>
T Pick(std::mt19937_64& rng, const std::vector<T>& values) {
  return values[static_cast<size_t>(UniformInt(rng, 0, static_cast<int>(values.size()) - 1))];
}

// A surface node that is not a support: a random face, a random node on it.
LatticeIndex RandomContactNode(std::mt19937_64& rng, const MeshSettings& mesh) {
  for (;;) {
    LatticeIndex node{UniformInt(rng, 0, mesh.nodes - 1), UniformInt(rng, 0, mesh.nodes - 1),
                      UniformInt(rng, 0, mesh.nodes - 1)};
    node[UniformInt(rng, 0, 2)] = UniformInt(rng, 0, 1) * (mesh.nodes - 1);
    if (!IsSupportNode(mesh, node)) return node;
  }
}

// One attempt at a case; ValidateScene decides whether it is kept.
StressCase DrawOnce(std::mt19937_64& rng, int index, const StressRanges& ranges) {
  StressCase c;
  c.index = index;
  Scene& s = c.scene;
  std::vector<int> node_counts;
  for (int n = ranges.min_nodes; n <= ranges.max_nodes; ++n) {
    if (n % 2 == 1) node_counts.push_back(n);
  }
  if (node_counts.empty()) node_counts.push_back(ranges.min_nodes);
  s.mesh.nodes = Pick(rng, node_counts);
  // Materials across and beyond the paper's ranges (E 5–20 kPa, ν 0.40–0.49, ρ 800–1200 kg/m³,
  // d 10–40 1/s).
  s.material.youngs_modulus_pa = LogUniform(rng, 2e3, 60e3);
  s.material.poisson_ratio = Uniform(rng, 0.30, 0.499);
  s.material.density_kg_m3 = Uniform(rng, 500, 2000);
  s.material.damping_per_s = Uniform(rng, 0, 60);
  // Extreme inputs: up to 5 cm at up to 20 Hz, anywhere on the surface.
  s.input.waveform = UniformInt(rng, 0, 1) ? Waveform::kSine : Waveform::kPress;
  s.input.amplitude_m = Uniform(rng, 0.001, 0.05);
  s.input.frequency_hz = LogUniform(rng, 0.2, 20);
  s.input.contact_node = RandomContactNode(rng, s.mesh);
  // Primary rates 500, 1000 and 2000 Hz; the secondary rates 50–100 % of it, in steps of 10 %.
  const int primary_hz = Pick(rng, std::vector<int>{500, 1000, 1000, 2000});
  s.solver.dt_s = 1.0 / primary_hz;
  std::vector<double> rates;
  for (int percent = 50; percent <= 100; percent += 10) rates.push_back(primary_hz * percent / 100);
  AdaptivitySettings& a = s.adaptivity;
  std::vector<int> lods;
  for (int k = 1; k <= 4; ++k) {
    if ((s.mesh.nodes - 1) % k == 0) lods.push_back(k);
  }
  a.secondary_lod = Pick(rng, lods);
  a.primary_size = UniformInt(rng, 1, 4);
  a.secondary_rate_hz = Pick(rng, rates);
  a.secondary_regions = UniformInt(rng, 0, 3) == 0 ? 2 : 1;
  a.outer_rate_hz = Pick(rng, rates);
  a.support_layers = UniformInt(rng, 0, 1);
  a.displacement_coupling = UniformInt(rng, 0, 4) != 0;
  c.substep_safety = AsyncRegions::kSubstepSafety;
  c.state_seed = static_cast<unsigned>(rng());
  return c;
}

// Puts one region's step at `ratio` of its own limit: one step per period everywhere, and the
// stiffness scaled (the limit goes as √(ρ/E), so E sets it exactly without changing the mesh).
void PlaceNearLimit(StressCase* c, int region_choice, double ratio) {
  constexpr double kNoSubsteps = 1e12;  // safety so large that every region takes one step
  const AsyncRegions probe(c->scene, kNoSubsteps);
  const int region = region_choice % probe.num_regions();
  const RegionSchedule& schedule = probe.schedule(region);
  if (!std::isfinite(schedule.alone.critical_dt_s)) return;  // nothing free to go unstable
  const double step = 1.0 / schedule.rate_hz;
  const double scale = schedule.alone.critical_dt_s * ratio / step;
  c->scene.material.youngs_modulus_pa *= scale * scale;
  c->substep_safety = kNoSubsteps;
}

}  // namespace

StressCase DrawStressCase(std::uint64_t seed, int index, const StressRanges& ranges) {
  std::mt19937_64 rng = CaseStream(seed, index);
  for (int attempt = 0; attempt < 1000; ++attempt) {
    StressCase c = DrawOnce(rng, index, ranges);
    // Two cases in five put one region's step near its own limit, on either side of it.
    const bool near_limit = UniformInt(rng, 0, 4) < 2;
    const int region_choice = UniformInt(rng, 0, 2);
    const double ratio = Uniform(rng, 0.8, 1.3);
    try {
      ValidateScene(c.scene);
      RegionPartition partition(c.scene);  // e.g. an outer shell left empty on a small mesh
      if (near_limit) PlaceNearLimit(&c, region_choice, ratio);
      return c;
    } catch (const Error&) {
      // e.g. a primary box covering the whole of a small mesh: draw again
    }
  }
  throw Error("no valid stress scene in 1000 draws: widen the node range");
}

long DetectionBoundPeriods(double spectral_radius, double common_period_s, double primary_dt_s) {
  const double periods_per_common = std::max(1.0, common_period_s / primary_dt_s);
  if (!(spectral_radius > 1)) return -1;  // not growing: no bound
  // Energy grows by ρ² per common period: the mode's energy share 1e-6 has to reach the factor.
  const double growth_needed = std::log(AsyncRegions::kEnergyGrowthFactor / 1e-20);
  const double common_periods =
      std::isfinite(spectral_radius) ? growth_needed / (2 * std::log(spectral_radius)) : 0;
  const double bound = (common_periods + 100) * periods_per_common;
  return bound > 1e12 ? static_cast<long>(1e12) : static_cast<long>(std::ceil(bound));
}

TrialResult RunAsTheDaemonRuns(AsyncRegions& regions, const InputSettings& input, unsigned seed,
                               StressOutcome* out) {
  regions.SetRandomState(seed);
  const double start_energy = regions.Energies().stored_j;
  TrialResult trial = regions.RunTrialFromRandomState(input, seed);
  const EnergyAccount e = regions.Energies();
  out->controlled_run = true;
  out->energy_gain_j = EnergyAboveBound(e, start_energy);
  out->energy_scale_j = std::max({start_energy, e.input_work_j, e.stored_j});
  out->backlog_bound_j = e.backlog_bound_j;
  return trial;
}

StressOutcome RunStressCase(const StressCase& stress_case, const StressRanges& ranges) {
  const auto start = std::chrono::steady_clock::now();
  StressOutcome out;
  out.stress_case = stress_case;
  const Scene& scene = stress_case.scene;
  // Predicted on the bare exchange, and run bare, so that what grows is what the prediction says
  // grows; a case whose regions meet their own limits runs again as the daemon runs it,
  // interface controllers on.
  AsyncRegions bare(scene, stress_case.substep_safety, AsyncRegions::InterfaceControl::kOff);
  out.regions = bare.num_regions();
  for (int r = 0; r < bare.num_regions(); ++r) {
    const RegionSchedule& schedule = bare.schedule(r);
    const double step = 1.0 / schedule.rate_hz / schedule.substeps;
    out.step_over_limit.push_back(step / schedule.alone.critical_dt_s);
    if (out.step_over_limit.back() >= 1) out.past_limit = true;
  }
  const CoupledStability coupled = bare.EstimateCoupledStability();
  out.spectral_radius = coupled.spectral_radius;
  out.common_period_s = coupled.common_period_s;
  out.coupling_only_unstable = !out.past_limit && !coupled.stable;
  out.predicted_stable = !out.past_limit && coupled.stable;
  double run_s = ranges.stable_run_s;
  if (!out.predicted_stable) {
    out.bound_periods =
        DetectionBoundPeriods(coupled.spectral_radius, coupled.common_period_s, scene.solver.dt_s);
    const double bound_s = static_cast<double>(out.bound_periods) * scene.solver.dt_s;
    out.marginal = out.bound_periods < 0 || bound_s > ranges.max_run_s;
    run_s = out.marginal ? ranges.max_run_s : bound_s;
  }
  InputSettings input = scene.input;
  input.periods = run_s * input.frequency_hz;
  // The prediction's check: the bare exchange, as predicted.
  const TrialResult trial = bare.RunTrialFromRandomState(input, stress_case.state_seed);
  out.outcome = trial.outcome;
  out.periods_run = trial.steps;
  out.peak_force_n = trial.peak_force_n;
  if (trial.diverged()) out.diverged_region = bare.LargestStateRegion();
  out.passive_expected = !out.past_limit &&
                         stress_case.substep_safety <= AsyncRegions::kSubstepSafety &&
                         scene.adaptivity.displacement_coupling;
  out.controlled_run = !out.past_limit;
  if (out.controlled_run) {
    // As the daemon runs it, interface controllers on: bounded too, and the object may hold no
    // more than the controllers guarantee (the tolerance is the one step the observer lags).
    bare.SetInterfaceControl(AsyncRegions::InterfaceControl::kPassive);
    out.controlled_outcome = RunAsTheDaemonRuns(bare, input, stress_case.state_seed, &out).outcome;
  }
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

TimingFaults StressTimingFaults(unsigned seed) {
  TimingFaults faults;
  faults.seed = seed;
  faults.secondary_lags_per_s = 2;
  faults.max_lag_periods = 10;
  faults.secondary_stalls_per_s = 0.5;
  faults.max_stall_s = 0.3;
  faults.primary_late_wakes_per_s = 2;
  faults.max_late_periods = 10;
  return faults;
}

namespace {
double LargestForceStep(const TrialResult& trial) {
  double largest = 0;
  for (size_t i = 1; i < trial.samples.size(); ++i) {
    const auto& f = trial.samples[i].feedback_force_n;
    const auto& g = trial.samples[i - 1].feedback_force_n;
    largest = std::max(largest, std::hypot(f[0] - g[0], f[1] - g[1], f[2] - g[2]));
  }
  return largest;
}
}  // namespace

FaultOutcome RunFaultCase(const StressOutcome& outcome, double run_s, const TimingFaults& faults) {
  FaultOutcome out;
  const bool production = outcome.stress_case.substep_safety <= AsyncRegions::kSubstepSafety;
  if (!production || !(outcome.predicted_stable || outcome.passive_expected)) return out;
  out.ran = true;
  Scene scene = outcome.stress_case.scene;
  scene.input.periods = run_s * scene.input.frequency_hz;
  AsyncRegions nominal(scene, outcome.stress_case.substep_safety);
  out.nominal_force_step_n = LargestForceStep(nominal.RunTrial());
  // The scale from the nominal run: a diverged run's own input work diverges with it.
  const EnergyAccount expected = nominal.Energies();
  out.energy_scale_j = std::max(
      {std::abs(expected.input_work_j), expected.damping_dissipated_j, expected.stored_j, 1e-12});
  AsyncRegions regions(scene, outcome.stress_case.substep_safety);
  RealTimeSchedule schedule(regions, 1.0, faults);
  const TrialResult trial = schedule.RunTrial();  // from rest
  out.outcome = trial.outcome;
  out.faults = schedule.faults();
  out.max_force_step_n = LargestForceStep(trial);
  const EnergyAccount e = regions.Energies();
  out.energy_gain_j = EnergyAboveBound(e, 0.0);
  out.backlog_bound_j = e.backlog_bound_j;
  out.diverged = trial.diverged() || !std::isfinite(e.stored_j) ||
                 e.stored_j > AsyncRegions::kEnergyGrowthFactor * out.energy_scale_j;
  return out;
}

std::string DescribeStressCase(const StressCase& c) {
  const Scene& s = c.scene;
  const AdaptivitySettings& a = s.adaptivity;
  const LatticeIndex node = ContactNode(s);
  std::ostringstream text;
  text << "case " << c.index << ": " << s.mesh.nodes << "³ nodes, E "
       << s.material.youngs_modulus_pa << " Pa, ν " << s.material.poisson_ratio << ", ρ "
       << s.material.density_kg_m3 << " kg/m³, d " << s.material.damping_per_s << " 1/s; "
       << WaveformName(s.input.waveform) << " " << s.input.amplitude_m << " m at "
       << s.input.frequency_hz << " Hz on node (" << node[0] << ", " << node[1] << ", " << node[2]
       << "); dt " << s.solver.dt_s << " s, primary_size " << a.primary_size << ", secondary_lod "
       << a.secondary_lod << ", secondary_rate " << a.secondary_rate_hz << " Hz, "
       << a.secondary_regions << " secondary region(s), outer_rate " << a.outer_rate_hz
       << " Hz, support_layers " << a.support_layers << ", coupling "
       << (a.displacement_coupling ? "displacement" : "force") << ", substep safety "
       << c.substep_safety;
  return text.str();
}

}  // namespace hapticsim
