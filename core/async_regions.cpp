#include "core/async_regions.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <random>

#include "core/error.hpp"

namespace hapticsim {
namespace {

using Clock = std::chrono::steady_clock;

Eigen::VectorXd MaskOf(int size, const std::vector<int>& dofs) {
  Eigen::VectorXd mask = Eigen::VectorXd::Zero(size);
  for (int dof : dofs) mask[dof] = 1.0;
  return mask;
}

// Value at time t on the line through two snapshots (the newer one alone if they coincide).
// Callers clamp t: a late writer must never be extrapolated far (see StepPrimary).
inline double OnLine(const BoundaryChannel::Snapshot& older, const BoundaryChannel::Snapshot& newer,
                     int i, double t) {
  const double span = newer.time_s - older.time_s;
  if (!(span > 0)) return newer.values[i];
  return newer.values[i] + (t - newer.time_s) / span * (newer.values[i] - older.values[i]);
}

}  // namespace

namespace {

// The primary elements that touch Γ, and their DOFs off Γ.
std::vector<int> BandElements(const RegionPartition& p) {
  std::vector<char> on_gamma(static_cast<size_t>(p.mesh().num_independent()), 0);
  const int nr = p.mesh().num_independent();
  for (int dof : p.interface_dofs()) on_gamma[dof % nr] = 1;
  std::vector<int> band;
  for (int e = 0; e < static_cast<int>(p.mesh().elements().size()); ++e) {
    const HybridElement& element = p.mesh().elements()[e];
    if (element.region != kPrimaryRegion) continue;
    bool touches = false;
    for (int node : element.nodes) {
      const auto [begin, end] = p.mesh().Gather(node);
      for (auto* g = begin; g != end; ++g) touches = touches || on_gamma[g->independent];
    }
    if (touches) band.push_back(e);
  }
  return band;
}

}  // namespace

AsyncRegions::AsyncRegions(const Scene& scene)
    : partition_(scene),
      coupling_(scene.adaptivity.displacement_coupling ? Coupling::kDisplacement : Coupling::kForce),
      band_stiffness_(std::make_unique<ElementSetStiffness>(partition_.mesh(), scene.material,
                                                            BandElements(partition_))),
      band_layer_([&] {
        std::vector<int> layer;
        const auto& gamma = partition_.interface_dofs();
        for (int dof : band_stiffness_->touched_dofs()) {
          if (!std::binary_search(gamma.begin(), gamma.end(), dof)) layer.push_back(dof);
        }
        return layer;
      }()),
      interface_displacement_(static_cast<int>(partition_.interface_dofs().size())),
      interface_force_(static_cast<int>(coupling_ == Coupling::kForce
                                            ? partition_.interface_dofs().size()
                                            : band_layer_.size())) {
  const RegionPartition& p = partition_;
  const int n = p.mesh().num_dofs();
  band_u_ = Eigen::VectorXd::Zero(n);
  band_ku_ = Eigen::VectorXd::Zero(n);
  const auto rate_p = static_cast<std::int64_t>(std::llround(PrimaryRateHz(scene)));
  const auto rate_s = static_cast<std::int64_t>(std::llround(scene.adaptivity.secondary_rate_hz));
  ticks_per_second_ = std::lcm(rate_p, rate_s);
  period_ticks_[kPrimaryRegion] = ticks_per_second_ / rate_p;
  period_ticks_[kSecondaryRegion] = ticks_per_second_ / rate_s;
  common_period_ticks_ = ticks_per_second_ / std::gcd(rate_p, rate_s);

  // Each region's own limit, its boundary held: the primary with Γ, contact and supports
  // prescribed; the secondary with its supports fixed and Γ free (carrying both sides' mass).
  schedules_[kPrimaryRegion].rate_hz = static_cast<double>(rate_p);
  schedules_[kSecondaryRegion].rate_hz = static_cast<double>(rate_s);
  schedules_[kPrimaryRegion].alone =
      EstimateStability(p.primary_stiffness(), p.dof_mass(), MaskOf(n, p.primary_owned()));
  schedules_[kSecondaryRegion].alone =
      EstimateStability(p.secondary_stiffness(), p.dof_mass(), MaskOf(n, p.secondary_owned()));
  for (RegionSchedule& s : schedules_) {
    const double period = 1.0 / s.rate_hz;
    s.substeps = std::max(1, static_cast<int>(std::ceil(period / (kSubstepSafety * s.alone.critical_dt_s))));
  }

  std::vector<int> primary_prescribed(p.contact_dofs().begin(), p.contact_dofs().end());
  primary_prescribed.insert(primary_prescribed.end(), p.primary_fixed().begin(), p.primary_fixed().end());
  primary_prescribed.insert(primary_prescribed.end(), p.interface_dofs().begin(), p.interface_dofs().end());
  const double damping = scene.material.damping_per_s;
  primary_ = std::make_unique<RegionIntegrator>(
      p.primary_stiffness(), p.dof_mass(), damping, p.primary_owned(), primary_prescribed,
      std::vector<int>{}, 1.0 / (static_cast<double>(rate_p) * schedules_[kPrimaryRegion].substeps));
  secondary_ = std::make_unique<RegionIntegrator>(
      p.secondary_stiffness(), p.dof_mass(), damping, p.secondary_owned(), p.secondary_fixed(),
      p.interface_dofs(), 1.0 / (static_cast<double>(rate_s) * schedules_[kSecondaryRegion].substeps));

  const int width = static_cast<int>(p.interface_dofs().size());
  for (auto* snapshot : {&displacement_newer_, &displacement_older_}) {
    snapshot->values = Eigen::VectorXd::Zero(width);
  }
  for (auto* snapshot : {&force_newer_, &force_older_}) {
    snapshot->values = Eigen::VectorXd::Zero(interface_force_.width());
  }
  primary_prescribed_.assign(primary_prescribed.size(), 0.0);
  secondary_prescribed_.assign(p.secondary_fixed().size(), 0.0);
  secondary_load_.assign(static_cast<size_t>(width), 0.0);
  interface_values_.assign(static_cast<size_t>(width), 0.0);
  force_values_.assign(static_cast<size_t>(interface_force_.width()), 0.0);
  Reset();
}

void AsyncRegions::PublishInitialSnapshots() {
  const auto& gamma = partition_.interface_dofs();
  const Eigen::VectorXd& us = secondary_->u();
  for (size_t i = 0; i < gamma.size(); ++i) interface_values_[i] = us[gamma[i]];
  interface_displacement_.Publish(0.0, interface_values_);
  PublishPrimarySide(0.0);
}

void AsyncRegions::PublishPrimarySide(double time_s) noexcept {
  if (coupling_ == Coupling::kForce) {
    const auto& gamma = partition_.interface_dofs();
    const Eigen::VectorXd& kp = primary_->Forces();
    for (size_t i = 0; i < gamma.size(); ++i) force_values_[i] = kp[gamma[i]];
  } else {
    const Eigen::VectorXd& up = primary_->u();
    for (size_t i = 0; i < band_layer_.size(); ++i) force_values_[i] = up[band_layer_[i]];
  }
  interface_force_.Publish(time_s, force_values_);
}

void AsyncRegions::Reset() {
  primary_->Reset();
  secondary_->Reset();
  interface_displacement_.Clear();
  interface_force_.Clear();
  state_ticks_[0] = state_ticks_[1] = 0;
  contact_now_ = {0, 0, 0};
  compute_s_[0] = compute_s_[1] = 0;
  PublishInitialSnapshots();
}

void AsyncRegions::SetRandomState(unsigned seed) {
  Reset();
  const int n = partition_.mesh().num_dofs();
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uniform(-1e-4, 1e-4);
  Eigen::VectorXd u = Eigen::VectorXd::Zero(n);
  for (int dof : partition_.primary_owned()) u[dof] = uniform(rng);
  for (int dof : partition_.secondary_owned()) u[dof] = uniform(rng);
  // Both copies hold the same values (Γ included); each region reads only its own DOFs.
  primary_->SetState(u, u);
  secondary_->SetState(u, u);
  interface_displacement_.Clear();
  interface_force_.Clear();
  PublishInitialSnapshots();
}

std::array<double, 3> AsyncRegions::StepPrimary(const std::array<double, 3>& contact_next) noexcept {
  const auto start = Clock::now();
  const auto& gamma = partition_.interface_dofs();
  const int substeps = schedules_[kPrimaryRegion].substeps;
  const double t0 = static_cast<double>(state_ticks_[kPrimaryRegion]) / ticks_per_second_;
  const double h = primary_->substep();
  // A failed read (writer racing ahead) keeps the previous snapshots: still a consistent pair.
  (void)interface_displacement_.TryReadLatestTwo(&displacement_newer_, &displacement_older_);
  const size_t fixed_end = 3 + partition_.primary_fixed().size();

  std::array<double, 3> reaction{};
  for (int q = 1; q <= substeps; ++q) {
    // The schedule keeps the secondary ahead, so Γ is interpolated. If it is late (a stalled
    // thread), Γ is held at its newest state rather than extrapolated: holding is what keeps the
    // primary bounded while the secondary catches up.
    const double t = std::min(t0 + q * h, displacement_newer_.time_s);
    const double fraction = static_cast<double>(q) / substeps;
    for (int c = 0; c < 3; ++c) {
      primary_prescribed_[c] = contact_now_[c] + fraction * (contact_next[c] - contact_now_[c]);
    }
    for (size_t i = 0; i < gamma.size(); ++i) {
      primary_prescribed_[fixed_end + i] =
          OnLine(displacement_older_, displacement_newer_, static_cast<int>(i), t);
    }
    primary_->Step(primary_prescribed_, {});
    if (q == 1) {
      for (int c = 0; c < 3; ++c) reaction[c] = primary_->PrescribedReaction(c);
    }
  }
  contact_now_ = contact_next;
  state_ticks_[kPrimaryRegion] += period_ticks_[kPrimaryRegion];

  PublishPrimarySide(static_cast<double>(state_ticks_[kPrimaryRegion]) / ticks_per_second_);
  compute_s_[kPrimaryRegion] += std::chrono::duration<double>(Clock::now() - start).count();
  return reaction;
}

void AsyncRegions::StepSecondary() noexcept {
  const auto start = Clock::now();
  const auto& gamma = partition_.interface_dofs();
  const int substeps = schedules_[kSecondaryRegion].substeps;
  const double t0 = static_cast<double>(state_ticks_[kSecondaryRegion]) / ticks_per_second_;
  const double h = secondary_->substep();
  (void)interface_force_.TryReadLatestTwo(&force_newer_, &force_older_);
  // The schedule puts the primary's newest state less than one primary period behind; never
  // extrapolate further than that, should the primary be late.
  const double newest_allowed = force_newer_.time_s + 1.0 / schedules_[kPrimaryRegion].rate_hz;
  for (int q = 0; q < substeps; ++q) {
    const double t = std::min(t0 + q * h, newest_allowed);
    if (coupling_ == Coupling::kForce) {
      for (size_t i = 0; i < gamma.size(); ++i) {
        secondary_load_[i] = -OnLine(force_older_, force_newer_, static_cast<int>(i), t);
      }
    } else {
      // (K_p u)_Γ from the band of primary elements on Γ: the primary's displacements next to Γ
      // on the line through its newest two states, Γ itself as the secondary has it now.
      for (size_t i = 0; i < band_layer_.size(); ++i) {
        band_u_[band_layer_[i]] = OnLine(force_older_, force_newer_, static_cast<int>(i), t);
      }
      const Eigen::VectorXd& us = secondary_->u();
      for (int dof : gamma) band_u_[dof] = us[dof];
      band_stiffness_->Apply(band_u_, band_ku_);
      for (size_t i = 0; i < gamma.size(); ++i) secondary_load_[i] = -band_ku_[gamma[i]];
    }
    secondary_->Step(secondary_prescribed_, secondary_load_);
  }
  state_ticks_[kSecondaryRegion] += period_ticks_[kSecondaryRegion];
  const Eigen::VectorXd& us = secondary_->u();
  for (size_t i = 0; i < gamma.size(); ++i) interface_values_[i] = us[gamma[i]];
  interface_displacement_.Publish(
      static_cast<double>(state_ticks_[kSecondaryRegion]) / ticks_per_second_, interface_values_);
  compute_s_[kSecondaryRegion] += std::chrono::duration<double>(Clock::now() - start).count();
}

double AsyncRegions::KineticEnergy() const noexcept {
  double kinetic = 0;
  const Eigen::VectorXd& m = partition_.dof_mass();
  for (const RegionIntegrator* region : {primary_.get(), secondary_.get()}) {
    const Eigen::VectorXd& u = region->u();
    const Eigen::VectorXd& up = region->u_previous();
    const double h = region->substep();
    for (int i : region->owned()) kinetic += m[i] * (u[i] - up[i]) * (u[i] - up[i]) / (h * h);
  }
  return 0.5 * kinetic;
}

double AsyncRegions::Energy() noexcept {
  double kinetic = 0, strain = 0;
  auto add = [&](RegionIntegrator& region) {
    const Eigen::VectorXd& ku = region.Forces();
    const Eigen::VectorXd& u = region.u();
    const Eigen::VectorXd& up = region.u_previous();
    const Eigen::VectorXd& m = partition_.dof_mass();
    const double h = region.substep();
    for (int i : region.owned()) kinetic += m[i] * (u[i] - up[i]) * (u[i] - up[i]) / (h * h);
    // Each DOF's strain term counted once overall: Γ by the secondary, the rest by its owner.
    for (int i : region.owned()) strain += u[i] * ku[i];
  };
  add(*primary_);
  add(*secondary_);
  // Γ rows: the primary's share of (K u)_Γ was left out above (Γ is owned by the secondary).
  const Eigen::VectorXd& kp = primary_->Forces();
  const Eigen::VectorXd& up = primary_->u();
  for (int i : partition_.interface_dofs()) strain += up[i] * kp[i];
  return 0.5 * (kinetic + strain);
}

void AsyncRegions::AdvanceSchedule(std::int64_t primary_target_ticks) {
  const std::array<double, 3> held{0, 0, 0};
  while (state_ticks_[kPrimaryRegion] < primary_target_ticks) {
    while (state_ticks_[kSecondaryRegion] <
           state_ticks_[kPrimaryRegion] + period_ticks_[kPrimaryRegion]) {
      StepSecondary();
    }
    StepPrimary(held);
  }
}

TrialResult AsyncRegions::RunTrial() {
  const Scene& scene = partition_.scene();
  TrialResult result;
  result.stability = schedules_[kPrimaryRegion].alone;
  Reset();
  const ContactTrajectory trajectory(scene.input);
  const double dt = 1.0 / schedules_[kPrimaryRegion].rate_hz;
  const long steps = scene.num_steps();
  result.samples.reserve(static_cast<size_t>(steps) + 1);
  const double budget = Energy();  // 0 from rest
  double work = 0;
  const auto start = Clock::now();
  for (long n = 0; n <= steps; ++n) {
    while (state_ticks_[kSecondaryRegion] <
           state_ticks_[kPrimaryRegion] + period_ticks_[kPrimaryRegion]) {
      StepSecondary();
    }
    const double t = n * dt;
    const double depth_next = trajectory.DepthAt(t + dt);
    const std::array<double, 3> r = StepPrimary({0.0, 0.0, depth_next});
    const double increment = r[2] * (depth_next - trajectory.DepthAt(t - dt)) / 2.0;
    if (increment > 0) work += increment;
    // The kinetic part alone is bounded by the same passivity budget and needs no extra K·u.
    const double energy = KineticEnergy();
    if (!std::isfinite(energy) || !std::isfinite(r[0] + r[1] + r[2])) {
      result.outcome = TrialOutcome::kDivergedNonFinite;
      break;
    }
    if (energy > kEnergyGrowthFactor * (budget + work) && energy > 0) {
      result.outcome = TrialOutcome::kDivergedEnergy;
      break;
    }
    ForceSample sample;
    sample.t_s = t;
    sample.contact_displacement_m = {0.0, 0.0, trajectory.DepthAt(t)};
    for (int c = 0; c < 3; ++c) sample.feedback_force_n[c] = -r[c];
    result.peak_force_n = std::max(result.peak_force_n, std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]));
    result.samples.push_back(sample);
    result.stopped_at_s = t;
    result.steps = n + 1;
  }
  result.wall_time_s = std::chrono::duration<double>(Clock::now() - start).count();
  return result;
}

CoupledStability AsyncRegions::EstimateCoupledStability(int burn_in_periods, int window_periods) {
  CoupledStability out;
  out.common_period_s = static_cast<double>(common_period_ticks_) / ticks_per_second_;
  SetRandomState(7);
  auto norm = [&] {
    return std::sqrt(primary_->OwnedStateNormSquared() + secondary_->OwnedStateNormSquared());
  };
  auto rescale = [&](double factor) {
    primary_->ScaleState(factor);
    secondary_->ScaleState(factor);
    interface_displacement_.ScaleAll(factor);
    interface_force_.ScaleAll(factor);
  };
  rescale(1.0 / norm());
  double log_growth = 0;
  for (int period = 1; period <= burn_in_periods + window_periods; ++period) {
    AdvanceSchedule(period * common_period_ticks_);
    const double size = norm();
    out.periods = period;
    if (!std::isfinite(size) || size > 1e100) {
      out.spectral_radius = INFINITY;
      out.stable = false;
      Reset();
      return out;
    }
    if (period > burn_in_periods) log_growth += std::log(size);
    rescale(1.0 / size);
  }
  out.spectral_radius = std::exp(log_growth / window_periods);
  out.stable = out.spectral_radius < CoupledStability::kStableBelow;
  Reset();
  return out;
}

std::vector<double> AsyncRegions::FreeDecayEnergies(int periods_per_checkpoint, int checkpoints,
                                                    unsigned seed) {
  SetRandomState(seed);
  std::vector<double> energies{Energy()};
  for (int c = 1; c <= checkpoints; ++c) {
    AdvanceSchedule(static_cast<std::int64_t>(c) * periods_per_checkpoint * common_period_ticks_);
    energies.push_back(Energy());
  }
  Reset();
  return energies;
}

}  // namespace hapticsim
