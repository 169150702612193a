#include "core/regions/async_regions.hpp"

#include <algorithm>
#include <cassert>
#include <chrono>
#include <cmath>
#include <random>

#include "core/error.hpp"
#include "core/regions/async_regions_region.hpp"
#include "core/regions/proxy_following.hpp"
#include "core/trial/proxy_contact.hpp"

namespace hapticsim {
namespace {

using Clock = std::chrono::steady_clock;

// The material the port floor is reckoned in: the object's one material, or of several the softest
// (the floor is an allowance, so the smaller) at the object's mean density (so mass / density is
// its volume).
Material FloorMaterial(const RegionPartition& p) {
  const int uniform = p.mesh().uniform_material();
  if (uniform >= 0) return p.materials()[uniform];
  Material floor = p.materials()[p.mesh().elements().front().material];  // one in use
  double volume_m3 = 0, mass_kg = 0;
  const double h = p.mesh().options().spacing_m;
  for (const HybridElement& e : p.mesh().elements()) {
    const Material& material = p.materials()[e.material];
    const double volume = std::pow(e.size_factor * h, 3);
    volume_m3 += volume;
    mass_kg += material.density_kg_m3 * volume;
    floor.youngs_modulus_pa = std::min(floor.youngs_modulus_pa, material.youngs_modulus_pa);
  }
  floor.density_kg_m3 = mass_kg / volume_m3;
  return floor;
}

}  // namespace

const RegionSchedule& AsyncRegions::schedule(RegionIndex region) const {
  return regions_[region]->schedule;
}
std::int64_t AsyncRegions::period_ticks(RegionIndex region) const {
  return regions_[region]->period_ticks;
}
std::int64_t AsyncRegions::state_ticks(RegionIndex region) const {
  return regions_[region]->state_ticks;
}
double AsyncRegions::compute_seconds(RegionIndex region) const {
  return regions_[region]->compute_s;
}

AsyncRegions::AsyncRegions(const Scene& scene, double substep_safety, InterfaceControl control)
    : partition_(scene),
      coupling_(scene.adaptivity.displacement_coupling ? Coupling::kDisplacement
                                                       : Coupling::kForce),
      control_(control) {
  if (!(substep_safety > 0)) throw Error("substep safety must be positive");
  substep_safety_ = substep_safety;
  const RegionPartition& p = partition_;
  primary_one_element_deep_ = p.PrimaryOneElementDeep();
  // A primary that follows a sliding proxy must reach every node its tip touches.
  if (p.proxy_contact()) CheckPrimaryReachesTip(scene, p.mesh().options().spacing_m);
  port_floor_j_ = PortFloorJ(FloorMaterial(p), p.dof_mass().sum() / 3.0);
  const int n = p.mesh().num_dofs();
  const int count = p.num_regions();
  // Each region's elements next to its outer Γ: what the region outwards evaluates on its Γ.
  std::vector<std::unique_ptr<ElementSetStiffness>> bands(static_cast<size_t>(count));
  for (int a = 0; a + 1 < count; ++a) {
    bands[a] =
        std::make_unique<ElementSetStiffness>(p.mesh(), p.materials(), p.outer_band_elements(a));
  }
  const double spring_omega2 = p.proxy_contact() ? SetUpProxy(scene.contact) : 0.0;
  const std::vector<RegionSchedule> schedules = ScheduleRegions(
      p, scene, bands, coupling_ == Coupling::kDisplacement, substep_safety, spring_omega2);
  std::vector<std::int64_t> rates;
  ticks_per_second_ = 1;
  for (const RegionSchedule& schedule : schedules) {
    rates.push_back(static_cast<std::int64_t>(schedule.rate_hz));
    ticks_per_second_ = std::lcm(ticks_per_second_, rates.back() * schedule.substeps);
  }
  common_period_ticks_ = 1;

  for (int a = 0; a < count; ++a) {
    auto region = std::make_unique<Region>();
    const RegionDofs& dofs = p.dofs(a);
    region->dofs = &dofs;
    region->schedule = schedules[a];
    region->period_ticks = ticks_per_second_ / (rates[a] * schedules[a].substeps);
    // The schedule repeats once every region has completed whole nominal periods.
    common_period_ticks_ = std::lcm(common_period_ticks_, ticks_per_second_ / rates[a]);
    BuildIntegrator(a, *region);
    // The outermost region's controller damps its inner Γ; a middle shell, with links on both
    // sides, and the primary (its last resort only), all their DOFs (ObserveInwardLink).
    if (a + 1 < count) region->integrator->SetControlledDofs(dofs.owned);
    if (a + 1 < count) region->integrator->SetPortPrescribedFrom(region->outer_offset);

    if (a + 1 < count) {
      region->band = std::move(bands[a]);
      for (int dof : region->band->touched_dofs()) {
        if (!std::binary_search(dofs.outer_interface.begin(), dofs.outer_interface.end(), dof)) {
          region->band_layer.push_back(dof);
        }
      }
      const std::vector<int>& owned = region->integrator->owned();  // ascending (RegionDofs)
      for (int dof : region->band_layer) {
        const auto at = std::lower_bound(owned.begin(), owned.end(), dof);
        region->band_layer_slot.push_back(
            at == owned.end() || *at != dof ? -1 : static_cast<int>(at - owned.begin()));
      }
      const int gamma = static_cast<int>(dofs.outer_interface.size());
      const int band = static_cast<int>(region->band_layer.size());
      const int outward_width = (coupling_ == Coupling::kForce ? gamma : 0) + 2 * band;
      region->inward = std::make_unique<BoundaryChannel>(gamma);
      region->outward = std::make_unique<BoundaryChannel>(outward_width);
      region->outer = BoundaryChannel::ReadPair(gamma);
      region->outward_values.assign(static_cast<size_t>(outward_width), 0.0);
    }
    if (a > 0) {
      const Region& inner = *regions_[a - 1];
      region->inner = BoundaryChannel::ReadPair(inner.outward->width());
      region->inward_values.assign(dofs.inner_interface.size(), 0.0);
      region->band_u = Eigen::VectorXd::Zero(n);
      region->band_ku = Eigen::VectorXd::Zero(n);
    }
    regions_.push_back(std::move(region));
  }
  BuildSurface();
  SetSteppingOrder(stepping_order_);  // the threads' release leads, whichever order runs
  Reset();
}

// Region a's integrator: its owned DOFs; prescribed, the contact (the primary's, unless a proxy
// pushes it), the supports and its outer Γ; loaded, its inner Γ (the primary: a proxy's face).
void AsyncRegions::BuildIntegrator(RegionIndex a, Region& region) {
  const RegionPartition& p = partition_;
  const RegionDofs& dofs = p.dofs(a);
  std::vector<int> prescribed;
  std::vector<int> loaded = dofs.inner_interface;
  if (a == kPrimaryRegion && p.proxy_contact()) {
    loaded = proxy_loaded_dofs_;
  } else if (a == kPrimaryRegion) {
    prescribed.assign(p.contact_dofs().begin(), p.contact_dofs().end());
  }
  prescribed.insert(prescribed.end(), dofs.fixed.begin(), dofs.fixed.end());
  region.outer_offset = prescribed.size();
  prescribed.insert(prescribed.end(), dofs.outer_interface.begin(), dofs.outer_interface.end());
  region.prescribed_values.assign(prescribed.size(), 0.0);
  region.load_values.assign(loaded.size(), 0.0);
  const double substep_s = 1.0 / region.schedule.rate_hz / region.schedule.substeps;
  region.integrator =
      std::make_unique<RegionIntegrator>(p.stiffness(a), p.dof_mass(), p.dof_damping(), dofs.owned,
                                         prescribed, std::move(loaded), substep_s);
}

// A stroke's proxy pushes the primary's face nodes through its spring (RegionPartition::
// proxy_contact): those are the primary's loaded DOFs. Returns the spring's k/m on the lightest of
// them, 1/s², which counts in the primary's own limit.
double AsyncRegions::SetUpProxy(const ContactSettings& contact) {
  const RegionPartition& p = partition_;
  const ProxyContact proxy(p.PrimaryProxySurface(), p.contact_node(), p.contact_normal(), contact);
  proxy_loaded_dofs_ = proxy.loaded_dofs();
  proxy_stiffness_n_per_m_ = contact.stiffness_n_per_m;
  const auto at =
      std::find(proxy_loaded_dofs_.begin(), proxy_loaded_dofs_.end(), p.contact_dofs()[0]);
  HAPTICSIM_THROW_UNLESS(at != proxy_loaded_dofs_.end(),
                         "internal: the proxy cannot push the contact node it starts on");
  proxy_contact_slot_ = static_cast<int>(at - proxy_loaded_dofs_.begin());
  return proxy_stiffness_n_per_m_ / proxy.lightest_loaded_mass_kg();
}

void AsyncRegions::PublishInitialSnapshots() {
  for (int a = 0; a < num_regions(); ++a) {
    if (a > 0) PublishInward(a);
    if (a + 1 < num_regions()) PublishOutward(a);
    PublishSurface(*regions_[a]);
  }
}

void AsyncRegions::PublishStep(RegionIndex a) noexcept {
  Region& region = *regions_[a];
  if (a > 0) PublishInward(a);
  if (region.inward) PublishOutward(a);
  if (surface_request_.load(std::memory_order_relaxed) != region.surface_request_served) {
    PublishSurface(region);
  }
}

void AsyncRegions::Reset() {
  for (auto& region : regions_) {
    region->integrator->Reset();
    if (region->inward) region->inward->Clear();
    if (region->outward) region->outward->Clear();
    region->state_ticks = 0;
    region->compute_s = 0;
    region->last_inexact_follow_ticks.store(INT64_MIN, std::memory_order_relaxed);
    region->no_lockstep_before_ticks = 0;
  }
  ResetEnergyAccount();
  primary_boundary_age_s_.store(0, std::memory_order_relaxed);
  PublishInitialSnapshots();
}

std::int64_t AsyncRegions::held_boundary_steps(RegionIndex inner) const noexcept {
  return regions_[inner]->held_boundary_steps.load(std::memory_order_relaxed);
}

bool AsyncRegions::RegionAtRest(RegionIndex region, double tolerance_m) const noexcept {
  return regions_[region]->integrator->OwnedStateMaxAbs() <= tolerance_m;
}

void AsyncRegions::SetRandomState(unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uniform(-1e-4, 1e-4);
  Eigen::VectorXd u = Eigen::VectorXd::Zero(partition_.mesh().num_dofs());
  for (int a = 0; a < num_regions(); ++a) {
    for (int dof : partition_.dofs(a).owned) u[dof] = uniform(rng);
  }
  StartFrom(u, Eigen::VectorXd::Zero(u.size()));
}

void AsyncRegions::StepRegionAt(RegionIndex a, const std::array<double, 3>* contact_next,
                                std::array<double, 3>* reaction, EndOfStepLoad* push) noexcept {
  const auto start = Clock::now();
  Region& region = *regions_[a];
  RegionIntegrator& integrator = *region.integrator;
  const double t0 = static_cast<double>(region.state_ticks) / ticks_per_second_;
  const double h = integrator.substep();
  const auto& outer_gamma = region.dofs->outer_interface;
  bool followed = true;  // this step's outer Γ is the outer region's own at the step's end
  bool held = false;     // … it is not: the outer region had not got that far (late)

  if (contact_next != nullptr && !partition_.proxy_contact()) {
    for (int c = 0; c < 3; ++c) region.prescribed_values[c] = (*contact_next)[c];
  }
  // A failed read (a writer racing ahead) keeps the previous snapshots: still a consistent pair.
  if (region.inward) {
    (void)region.inward->TryReadLatestTwo(&region.outer);
    // The outer region is ahead: interpolate. If it is late, hold its newest state.
    const double t = std::min(t0 + h, region.outer.newer.time_s);
    const double end =
        static_cast<double>(region.state_ticks + region.period_ticks) / ticks_per_second_;
    // On the line between the two snapshots, not held short of it nor clamped to a later one.
    followed = region.outer.older.time_s <= end && end <= region.outer.newer.time_s;
    held = end > region.outer.newer.time_s;
    if (a == kPrimaryRegion) {
      primary_boundary_age_s_.store(t0 + h - t, std::memory_order_relaxed);
    }
    for (size_t i = 0; i < outer_gamma.size(); ++i) {
      region.prescribed_values[region.outer_offset + i] =
          OnLine(region.outer.older, region.outer.newer, static_cast<int>(i), t);
    }
  }
  if (a > 0) ReadInnerLoads(a, t0);
  double asked_inward = 0, asked_outward = 0;
  PortWorkLimits limits;
  if (control_ != InterfaceControl::kOff)
    ControlInterfaces(a, &asked_inward, &asked_outward, &limits);
  if (push != nullptr) {
    integrator.Step(region.prescribed_values, *push, asked_inward + asked_outward, limits);
  } else {
    integrator.Step(region.prescribed_values, region.load_values, asked_inward + asked_outward,
                    limits);
  }
  if (reaction != nullptr && !partition_.proxy_contact()) {
    for (int c = 0; c < 3; ++c) (*reaction)[c] = integrator.PrescribedReaction(c);
  }
  AccountStep(a, asked_inward, asked_outward);
  region.state_ticks += region.period_ticks;
  if (region.inward && (!followed || integrator.PrescribedWorkRefused() > 0)) {
    region.last_inexact_follow_ticks.store(region.state_ticks, std::memory_order_release);
  }
  if (held) region.held_boundary_steps.fetch_add(1, std::memory_order_relaxed);
  PublishStep(a);
  region.compute_s += std::chrono::duration<double>(Clock::now() - start).count();
}

std::array<double, 3> AsyncRegions::StepPrimary(
    const std::array<double, 3>& contact_next) noexcept {
  std::array<double, 3> reaction{};
  StepRegionAt(kPrimaryRegion, &contact_next, &reaction);
  return reaction;
}

void AsyncRegions::StepPrimaryPushed(EndOfStepLoad& push) noexcept {
  assert(partition_.proxy_contact());
  StepRegionAt(kPrimaryRegion, nullptr, nullptr, &push);
}

namespace {
// The stability estimate's contact: a stroke's proxy at rest on its start node, the tool held
// there. The spring pulls the contact node back to rest, −k·u⁺, taken at the step's end as every
// proxy's push is (ProxyPush): u⁺ = ũ + c·f gives f = −k·ũ / (1 + k·c).
class HeldToolSpring final : public EndOfStepLoad {
 public:
  HeldToolSpring(double stiffness_n_per_m, int contact_slot, const std::array<int, 3>& dofs)
      : k_(stiffness_n_per_m), slot_(contact_slot), dofs_(dofs) {}
  void Load(const Eigen::VectorXd& predicted, std::span<const double> compliance,
            std::span<double> load) noexcept override {
    std::fill(load.begin(), load.end(), 0.0);
    for (int c = 0; c < 3; ++c) {
      const auto slot = static_cast<std::size_t>(slot_ + c);
      load[slot] = -k_ * predicted[dofs_[c]] / (1.0 + k_ * compliance[slot]);
    }
  }

 private:
  double k_;
  int slot_;
  std::array<int, 3> dofs_;
};
}  // namespace

const Eigen::VectorXd& AsyncRegions::primary_state() const noexcept {
  return regions_[kPrimaryRegion]->integrator->u();
}

std::array<double, 3> AsyncRegions::primary_contact_m() const noexcept {
  const Eigen::VectorXd& u = regions_[kPrimaryRegion]->integrator->u();
  const std::array<int, 3>& dofs = partition_.contact_dofs();
  return {u[dofs[0]], u[dofs[1]], u[dofs[2]]};
}

void AsyncRegions::StepRegion(RegionIndex region) noexcept {
  StepRegionAt(region, nullptr, nullptr);
}

void AsyncRegions::SkipRegion(RegionIndex a, std::int64_t steps) noexcept {
  if (a == kPrimaryRegion || steps <= 0) return;
  Region& region = *regions_[a];
  // Published twice, one step apart, with the same values: a flat line, so a neighbour reading
  // between them holds the state instead of interpolating towards the time before the stall.
  region.state_ticks += (steps - 1) * region.period_ticks;
  // Neither link is in lock-step across a skip: its band and Γ are the state before the stall.
  if (region.inward) {
    region.last_inexact_follow_ticks.store(region.state_ticks + region.period_ticks,
                                           std::memory_order_release);
  }
  region.no_lockstep_before_ticks = region.state_ticks + 3 * region.period_ticks;
  for (int twice = 0; twice < 2; ++twice) {
    PublishInward(a);
    if (region.inward) PublishOutward(a);
    if (twice == 0) region.state_ticks += region.period_ticks;
  }
}

void AsyncRegions::AdvanceRegionTo(RegionIndex a, std::int64_t ticks) noexcept {
  Region& region = *regions_[a];
  while (region.state_ticks < ticks) {
    // Before this region steps to t + P, the region outwards must supply Γ at t + P.
    if (a + 1 < num_regions()) AdvanceRegionTo(a + 1, region.state_ticks + region.period_ticks);
    StepRegion(a);
  }
}

void AsyncRegions::AdvanceSecondariesTo(std::int64_t ticks) noexcept {
  if (num_regions() > 1) AdvanceRegionTo(1, ticks);
}

void AsyncRegions::AdvancePrimaryTo(std::int64_t ticks) noexcept {
  const std::array<double, 3> held{0, 0, 0};
  Region& primary = *regions_[kPrimaryRegion];
  while (primary.state_ticks < ticks) {
    AdvanceSecondariesForPrimaryStep();
    if (partition_.proxy_contact()) {
      HeldToolSpring spring(proxy_stiffness_n_per_m_, proxy_contact_slot_,
                            partition_.contact_dofs());
      StepPrimaryPushed(spring);
    } else {
      StepPrimary(held);
    }
  }
}

double AsyncRegions::KineticEnergy() const noexcept {
  double kinetic = 0;
  const Eigen::VectorXd& m = partition_.dof_mass();
  for (const auto& region : regions_) {
    const Eigen::VectorXd &u = region->integrator->u(), &up = region->integrator->u_previous();
    double sum = 0;  // Σ m (u − u⁻)², divided by h² once per region
    for (int i : region->dofs->owned) sum += m[i] * (u[i] - up[i]) * (u[i] - up[i]);
    kinetic += sum / std::pow(region->integrator->substep(), 2);
  }
  return 0.5 * kinetic;
}

double AsyncRegions::Energy() noexcept {
  double energy = 0;
  for (auto& region : regions_) energy += region->integrator->StateEnergy();
  return energy;
}

}  // namespace hapticsim
