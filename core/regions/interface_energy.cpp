// The coupling's energy, per interface and in all (docs/regions.md, "Passive interfaces"): the
// interface controllers (observers kept by the outer side of each link), the port limits, the
// energy balance each region keeps of its own steps (AccountStep) and what the threads publish of
// it (PublishedBalance, which the daemon's runaway watch reads). AsyncRegions::StepRegionAt calls
// these around each region's step.
#include <algorithm>
#include <cmath>

#include "core/regions/async_regions.hpp"
#include "core/regions/async_regions_region.hpp"

namespace hapticsim {

// The energy of the whole object at a uniform strain of kPortFloorStrain, ½ E ε² V: the
// allowance when both regions' energies are still zero. Early in a press they are, while a
// lagged exchange already moves energy across Γ; with no floor every first step of a multirate
// press would be refused. (At equal rates lock-step covers that; before lock-step was
// recognised, a floor of 10⁻⁷ J — a strain of 3.6 × 10⁻⁵ on the default scene — left every
// equal-rate press of the tests untouched, 10⁻⁹ J did not.)
double AsyncRegions::PortFloorJ(const Material& material, double mass_kg) {
  const double volume = mass_kg / material.density_kg_m3;
  return 0.5 * material.youngs_modulus_pa * kPortFloorStrain * kPortFloorStrain * volume;
}

AsyncRegions::~AsyncRegions() = default;

// The interface controllers. Each link between region a − 1 (inner) and region a (outer, which
// owns their Γ) has one observer, `excess`, kept by the outer side: the energy the exchange
// created — the inner side's work through Γ as last published, the outer side's load work — less
// what both sides' controllers took out and kDampingCredit of the outer region's material damping.
// Whatever is above zero comes out of the outer side's next step, as extra damping on the DOFs it
// controls (RegionIntegrator::Step: its Γ, or, a middle shell, all its DOFs). What one step
// cannot take (a growing mode can live inside the inner region, where Γ barely moves) an inner
// middle shell takes out of all its DOFs at its next step — never the primary, where damping is
// a force at the contact the user feels. Both may act on the same excess before each
// has seen the other's step: more damping, never less. Credit below zero is kept down to
// −kCreditMemory of the outer region's energy, so an interface that dissipated for an hour cannot
// then create an hour's worth before the controllers act. Since that floor only ever raises the
// observer, created − taken out ≤ kDampingCredit × the secondaries' damping + the observers'
// positive excess, whatever the timing. That excess is what the controllers have not yet
// managed to take out: one step's worth while they keep up; where a mode outgrows them (the
// force exchange was measured to), the port limits below bound it. (In some stiff scenes a
// region's own discrete energy is not positive, and then no bound on it bounds the state: the
// runaway watch, Runaway, sees the state itself — docs/regions.md, "The runaway watch".)

// Whether the port limits act on the link outwards of region `inner` (docs/regions.md, "The port
// limits"): with the force exchange, which the controllers alone were measured not to hold; and
// with the displacement exchange where the link runs at another rate, unless its inner region is
// a primary one element deep. hapticsimd's threads run such a link with the outer region a whole
// period of substeps ahead, reading the inner band extrapolated and held: on a stiff cube (stress
// seed 1, case 970) the exchange created 78–112 J on threads against 1.3 mJ in virtual time, more
// than one step's damping on Γ takes out. A primary one element deep is left to the runaway
// watch: its discrete energy says little about its state, so the limits cannot tell a step's
// honest flow from a created one — under fast inputs they cost up to 50 points of error, and
// where its state runs away (case 160) they hold it bounded at 186 % from the reference instead
// of the watch taking the regions to equal rates.
bool AsyncRegions::PortLimited(RegionIndex inner) const noexcept {
  if (control_ != InterfaceControl::kPassive) return false;
  if (coupling_ == Coupling::kForce) return true;
  if (AtOneRate(inner)) return false;
  return !(inner == kPrimaryRegion && primary_one_element_deep_);
}

// Before region a's step: publishes its energies, and returns what its controllers are to take
// out for its link inwards and outwards and, where the port limits act, the most its ports may do.
void AsyncRegions::ControlInterfaces(RegionIndex a, double* asked_inward, double* asked_outward,
                                     PortWorkLimits* limits) noexcept {
  Region& region = *regions_[a];
  // An O(n) pass over the region's DOFs (K·u is cached for the step): the controllers' floor
  // and the port limits follow the energy step by step, and the runaway watch the state's.
  const RegionIntegrator::Energies energies = region.integrator->BothEnergies();
  const double energy = std::max(0.0, energies.discrete_j);
  region.energy_published.store(energy, std::memory_order_relaxed);
  region.state_energy_published.store(energies.state_j, std::memory_order_relaxed);
  region.energy_peak = std::max(region.energy_peak, energy);
  if (a > 0) {
    *asked_inward = ObserveInwardLink(a, energy);
    if (PortLimited(a - 1)) limits->load_work_j = InwardPortLimit(a, energy, InLockStep(a));
  }
  if (region.inward) {
    *asked_outward = OutwardLinkExcess(a);
    if (PortLimited(a)) limits->prescribed_work_j = OutwardPortLimit(a, energy);
  }
  // The primary keeps kPrimaryReserve of its energy in reserve: damping its DOFs is a viscous
  // force at the contact the user feels (measured: a loaded press peaked 14 % high when it took
  // every step's backlog), so it acts only on a backlog the shells have let grow past that.
  if (a == kPrimaryRegion && *asked_outward > 0) {
    *asked_outward = std::max(0.0, *asked_outward - kPrimaryReserve * energy);
  }
}

// The outer side, before its step: folds in what the inner side published and returns the excess.
double AsyncRegions::ObserveInwardLink(RegionIndex a, double energy) noexcept {
  Region& region = *regions_[a];
  const Region& inner = *regions_[a - 1];
  const double work = inner.outer_gamma_work_published.load(std::memory_order_relaxed);
  const double taken = inner.outward_taken_published.load(std::memory_order_relaxed);
  region.excess += (work - region.inner_work_seen) - (taken - region.inner_taken_seen);
  region.inner_work_seen = work;
  region.inner_taken_seen = taken;
  if (region.excess < 0) {
    // The floor follows the region's energy step by step: refreshed only every 16 steps it was
    // measured to cost up to 0.27 points of accuracy, a stale small floor cutting the credit
    // early in a press.
    region.excess = std::max(-kCreditMemory * energy, region.excess);
  }
  return std::max(0.0, region.excess);
}

double AsyncRegions::PrimaryReserve(RegionIntegrator& primary) noexcept {
  return kPrimaryReserve * std::max(0.0, primary.DiscreteEnergy());
}

// The port limits: the last line, for what the controllers cannot take out in time (a mode that
// outgrows one step's damping, a neighbour late or stalled). Each side of a link lets its port
// do work only while the link's observer, as that side can know it, stays below the link's
// allowance: kPortAllowance of the two regions' energies plus a floor (PortFloorJ). The outer
// side knows the observer as of the inner side's last publication; the inner side knows it as of
// the outer side's last publication plus its own sums since (exactly). Either view misses only
// what the other side did since, and that side held itself to the allowance from its own view:
// so EnergyAboveBound never exceeds the two allowances, the credit the floor keeps
// (kCreditMemory) and what lock-step let in unlimited (InLockStep), whatever the timing
// (docs/regions.md, "The port limits").
double AsyncRegions::InwardPortLimit(RegionIndex a, double energy, bool lockstep) noexcept {
  Region& region = *regions_[a];
  const Region& inner = *regions_[a - 1];
  const double allowance =
      kPortAllowance * (energy + inner.energy_published.load(std::memory_order_relaxed)) +
      port_floor_j_;
  region.inward_allowance_peak = std::max(region.inward_allowance_peak, allowance);
  region.lockstep_step = lockstep && region.excess <= allowance;
  if (region.lockstep_step) return INFINITY;
  return std::max(0.0, allowance - region.excess);
}

// Lock-step: the inner region steps with this one's period, its newest band is at this step's
// start, and its last two steps followed this region's Γ exactly. Then the exchange of this step
// is monolithic central difference: the inner side's coming step gives out what this one takes
// in (the load is the inner band's force at this step's start, on the Γ motion this step makes),
// but this side, stepping first, cannot yet see it — one step's flow, which at equal rates can
// exceed the allowance many times over (a 20 Hz sine on primary_size 1: 44 % of error when it
// was limited). So the load goes unlimited in lock-step while the observer is under the
// allowance. Should the inner side then not follow (a late thread holds Γ), what this step took
// in unmatched is at most its load work, which lockstep_load_peak keeps for the bound.
bool AsyncRegions::InLockStep(RegionIndex a) const noexcept {
  const Region& region = *regions_[a];
  const Region& inner = *regions_[a - 1];
  return region.state_ticks >= region.no_lockstep_before_ticks &&
         inner.period_ticks == region.period_ticks &&
         region.inner.newer.time_s == static_cast<double>(region.state_ticks) / ticks_per_second_ &&
         inner.last_inexact_follow_ticks.load(std::memory_order_acquire) <
             region.state_ticks - region.period_ticks;
}

double AsyncRegions::OutwardPortLimit(RegionIndex a, double energy) noexcept {
  Region& region = *regions_[a];
  const Region& outer = *regions_[a + 1];
  const double allowance =
      kPortAllowance * (energy + outer.energy_published.load(std::memory_order_relaxed)) +
      port_floor_j_;
  region.outward_allowance_peak = std::max(region.outward_allowance_peak, allowance);
  const double observer = outer.excess_base_published.load(std::memory_order_relaxed) +
                          region.outer_gamma_work - region.outward_taken;
  return std::max(0.0, allowance - observer);
}

// The inner side, before its step: what the outer side's last step could not take out, less
// what this side has taken since the outer side counted it.
double AsyncRegions::OutwardLinkExcess(RegionIndex a) const noexcept {
  const Region& region = *regions_[a];
  const Region& outer = *regions_[a + 1];
  const double excess =
      outer.unmet_published.load(std::memory_order_relaxed) -
      (region.outward_taken - outer.inner_taken_seen_published.load(std::memory_order_relaxed));
  return std::max(0.0, excess);
}

void AsyncRegions::AccountStep(RegionIndex a, double asked_inward, double asked_outward) noexcept {
  Region& region = *regions_[a];
  const RegionIntegrator& integrator = *region.integrator;
  region.damping_dissipated += integrator.DampingDissipated();
  region.port_refused += integrator.LoadWorkRefused() + integrator.PrescribedWorkRefused();
  // What the step took out, shared between the two links in proportion to what each asked.
  const double asked = asked_inward + asked_outward;
  const double taken = integrator.ControlledDissipated();
  const double taken_inward = asked > 0 ? taken * asked_inward / asked : 0.0;
  if (a == kPrimaryRegion && partition_.proxy_contact()) {
    region.input_work += integrator.LoadWork();  // the proxy's spring
  } else if (a == kPrimaryRegion) {
    for (int c = 0; c < 3; ++c) region.input_work += integrator.PrescribedWork(c);
  }
  if (a > 0) {
    if (region.lockstep_step) {
      region.lockstep_load_peak = std::max(region.lockstep_load_peak, integrator.LoadWork());
      region.lockstep_step = false;
    }
    region.inner_gamma_load_work += integrator.LoadWork();
    region.inward_taken += taken_inward;
    region.unmet = std::max(0.0, asked_inward - taken_inward);
    region.excess +=
        integrator.LoadWork() - taken_inward - kDampingCredit * integrator.DampingDissipated();
  }
  if (region.inward) {
    const size_t end = region.outer_offset + region.dofs->outer_interface.size();
    for (size_t k = region.outer_offset; k < end; ++k) {
      region.outer_gamma_work += integrator.PrescribedWork(static_cast<int>(k));
    }
    region.outward_taken += taken - taken_inward;
  }
  PublishEnergyAccount(region);
}

void AsyncRegions::PublishEnergyAccount(Region& region) noexcept {
  region.input_work_published.store(region.input_work, std::memory_order_relaxed);
  region.damping_published.store(region.damping_dissipated, std::memory_order_relaxed);
  region.outer_gamma_work_published.store(region.outer_gamma_work, std::memory_order_relaxed);
  region.outward_taken_published.store(region.outward_taken, std::memory_order_relaxed);
  region.unmet_published.store(region.unmet, std::memory_order_relaxed);
  region.inner_taken_seen_published.store(region.inner_taken_seen, std::memory_order_relaxed);
  region.excess_base_published.store(
      region.excess - (region.inner_work_seen - region.inner_taken_seen),
      std::memory_order_relaxed);
}

void AsyncRegions::ResetEnergyAccount() noexcept {
  state_energy_at_reset_j_ = 0;
  for (auto& region : regions_) {
    region->input_work = region->damping_dissipated = region->port_refused = 0;
    region->inward_allowance_peak = region->outward_allowance_peak = region->energy_peak = 0;
    region->lockstep_load_peak = 0;
    region->lockstep_step = false;
    region->outer_gamma_work = region->outward_taken = 0;
    region->inner_gamma_load_work = region->inward_taken = region->excess = region->unmet = 0;
    region->inner_work_seen = region->inner_taken_seen = 0;
    const RegionIntegrator::Energies energies = region->integrator->BothEnergies();
    region->energy_published.store(std::max(0.0, energies.discrete_j), std::memory_order_relaxed);
    region->state_energy_published.store(energies.state_j, std::memory_order_relaxed);
    state_energy_at_reset_j_ += energies.state_j;
    PublishEnergyAccount(*region);
  }
}

EnergyAccount AsyncRegions::Energies() noexcept {
  EnergyAccount account;
  if (control_ != InterfaceControl::kOff && num_regions() > 1) {
    account.primary_reserve_j = PrimaryReserve(*regions_[kPrimaryRegion]->integrator);
  }
  for (int a = 0; a < num_regions(); ++a) {
    Region& region = *regions_[a];
    account.stored_j += region.integrator->DiscreteEnergy();
    account.input_work_j += region.input_work;
    account.damping_dissipated_j += region.damping_dissipated;
    account.port_refused_j += region.port_refused;
    if (a > 0) account.credited_damping_j += region.damping_dissipated;
    account.interface_created_j += region.outer_gamma_work + region.inner_gamma_load_work;
    account.interface_dissipated_j += region.inward_taken + region.outward_taken;
    if (a > 0) {
      const Region& inner = *regions_[a - 1];
      if (PortLimited(a - 1)) {
        account.backlog_bound_j += inner.outward_allowance_peak + region.inward_allowance_peak +
                                   kCreditMemory * region.energy_peak + region.lockstep_load_peak;
      }
      account.pending_excess_j += region.excess +
                                  (inner.outer_gamma_work - region.inner_work_seen) -
                                  (inner.outward_taken - region.inner_taken_seen);
    }
  }
  return account;
}

double AsyncRegions::InputWorkJ() const noexcept {
  double work = 0;
  for (const auto& region : regions_) work += region->input_work;
  return work;
}

AsyncRegions::PublishedBalanceView AsyncRegions::PublishedBalance() const noexcept {
  PublishedBalanceView view;
  for (int a = 0; a < num_regions(); ++a) {
    const Region& region = *regions_[a];
    const double energy = region.energy_published.load(std::memory_order_relaxed);
    view.stored_j += energy;
    view.state_energy_j += region.state_energy_published.load(std::memory_order_relaxed);
    const double damping = region.damping_published.load(std::memory_order_relaxed);
    view.allowed_j += region.input_work_published.load(std::memory_order_relaxed) -
                      (a == kPrimaryRegion ? 1.0 : 1.0 - kDampingCredit) * damping;
    if (a == 0) {
      if (num_regions() > 1) view.primary_reserve_j = kPrimaryReserve * energy;
      continue;
    }
    const Region& inner = *regions_[a - 1];
    // As in Energies: the observer's base plus the inner side's own sums, both as published.
    const double pending = region.excess_base_published.load(std::memory_order_relaxed) +
                           inner.outer_gamma_work_published.load(std::memory_order_relaxed) -
                           inner.outward_taken_published.load(std::memory_order_relaxed);
    view.backlog_j += std::max(0.0, pending);
  }
  view.allowed_j += state_energy_at_reset_j_ + view.primary_reserve_j;
  return view;
}
}  // namespace hapticsim
