#include <algorithm>

#include "core/regions/async_regions.hpp"
#include "core/regions/async_regions_region.hpp"

// What crosses an interface Γ between regions a (inner) and a + 1 (outer): the outer region's
// displacements on Γ inwards, and outwards the inner region's forces on Γ or its band next to Γ
// (AsyncRegions' class comment); who publishes what after a step, and how a region reads its
// inner neighbour's load on Γ.
namespace hapticsim {

void AsyncRegions::PublishInward(RegionIndex a) noexcept {
  Region& region = *regions_[a];
  const Eigen::VectorXd& u = region.integrator->u();
  const auto& gamma = region.dofs->inner_interface;
  for (size_t i = 0; i < gamma.size(); ++i) region.inward_values[i] = u[gamma[i]];
  regions_[a - 1]->inward->Publish(static_cast<double>(region.state_ticks) / ticks_per_second_,
                                   region.inward_values);
}

void AsyncRegions::PublishOutward(RegionIndex a) noexcept {
  Region& region = *regions_[a];
  RegionIntegrator& integrator = *region.integrator;
  const Eigen::VectorXd& u = integrator.u();
  const size_t n = region.band_layer.size();
  // [the forces on Γ (force exchange)] [the band now] [the band after the next step]: see
  // BandOffset and ReadInnerLoads.
  if (coupling_ == Coupling::kForce) {
    const Eigen::VectorXd& ku = integrator.Forces();
    const auto& gamma = region.dofs->outer_interface;
    for (size_t i = 0; i < gamma.size(); ++i) region.outward_values[i] = ku[gamma[i]];
  }
  const size_t band_at = BandOffset(a);
  // Where the next step puts the band only matters to an outer region at this one's rate; the
  // force exchange's band to nothing else (ReadInnerLoads).
  const bool next_read = AtOneRate(a);
  const size_t band_read = coupling_ == Coupling::kForce && !next_read ? 0 : n;
  for (size_t i = 0; i < band_read; ++i) {
    const double now = u[region.band_layer[i]];
    const int slot = region.band_layer_slot[i];
    region.outward_values[band_at + i] = now;
    region.outward_values[band_at + n + i] =
        next_read && slot >= 0 ? integrator.NextBeforeLoads(slot) : now;
  }
  region.outward->Publish(static_cast<double>(region.state_ticks) / ticks_per_second_,
                          region.outward_values);
}

// Regions `inner` and inner + 1 at one rate (and so in steps as long: ScheduleRegions gives
// neighbours at one rate the same substeps): the link whose outer thread is released half a
// period ahead (ReleaseLeadsNs) and reads the inner band's next step.
bool AsyncRegions::AtOneRate(RegionIndex inner) const noexcept {
  return regions_[inner]->schedule.rate_hz == regions_[inner + 1]->schedule.rate_hz;
}

// Where region `inner`'s outward snapshot holds its band (after its forces on Γ, with the force
// exchange); its band after the next step follows.
size_t AsyncRegions::BandOffset(RegionIndex inner) const noexcept {
  return coupling_ == Coupling::kForce ? regions_[inner]->dofs->outer_interface.size() : 0;
}

// Region a's load on its inner Γ at t0: the inner region's force there, from its newest two
// snapshots (the force exchange at another rate), or from its displacements next to Γ (the
// displacement exchange; at one rate, either).
void AsyncRegions::ReadInnerLoads(RegionIndex a, double t0) noexcept {
  Region& region = *regions_[a];
  const auto& inner_gamma = region.dofs->inner_interface;
  RegionIntegrator& integrator = *region.integrator;
  const Region& inner = *regions_[a - 1];
  (void)inner.outward->TryReadLatestTwo(&region.inner);
  // The schedule keeps the inner region less than one of its nominal periods behind. Never
  // extrapolate its snapshots further than one of its steps (one substep): the line through
  // two substeps' snapshots, carried a whole period of s substeps ahead, multiplies their
  // difference by s, and a stiff object's Γ oscillating from substep to substep diverged so
  // (the palpation phantom at 2.5 mm, 6 substeps: the force grew ×−5 a period in real time).
  //
  // At this region's rate in steps as long (AtOneRate), the inner region is at t0 itself
  // (stepped in order, or on threads released as ReleaseLeadsNs says), except on a thread that
  // takes its period's substeps at once: its later ones come before the inner region has taken
  // its own. Those read the band where the inner region's next step will put it, which the inner
  // region published with its state (one substep on, exact but for a prescribed DOF in the band,
  // which is held: 2 substeps a period exchange as in order), and hold that beyond. The line
  // carried on instead overshoots through a mode that turns most of the way from substep to
  // substep: hapticsimd serving the organ sample (2 substeps at one rate) pressed with 1.4 N where
  // the static solution is 0.16 N.
  //
  // At one rate the force exchange is the displacement exchange: on time, the inner region's Γ
  // is this region's own, so its band's force on Γ is the force it would publish; late, the band
  // with this region's Γ as it is now stays passive, where the inner region's forces carry its
  // stale view of Γ. Measured on threads, the stiff cube of RealTimeSchedule's test in 2
  // substeps at one rate, with the force's line carried a substep: 6.4 % from the virtual-time
  // run at real time, the exchange making 35 % of the input's work; with 10 late primary wakes
  // and 10 secondary lags a second (1–2 periods), 9–14 % and 60–110 % in six runs.
  const double inner_step_s = 1.0 / (inner.schedule.rate_hz * inner.schedule.substeps);
  const bool equal_steps = AtOneRate(a - 1);
  const double t = std::min(t0, region.inner.newer.time_s + (equal_steps ? 0.0 : inner_step_s));
  if (coupling_ == Coupling::kForce && !equal_steps) {
    for (size_t i = 0; i < inner_gamma.size(); ++i) {
      region.load_values[i] =
          -OnLine(region.inner.older, region.inner.newer, static_cast<int>(i), t);
    }
    return;
  }
  // The inner region's force on Γ from its band: its displacements next to Γ on the line through
  // its newest two states (or next, as above), Γ itself as this region has it now.
  const size_t n = inner.band_layer.size();
  const size_t band_at = BandOffset(a - 1);
  const bool next = equal_steps && t0 > region.inner.newer.time_s;
  for (size_t i = 0; i < n; ++i) {
    region.band_u[inner.band_layer[i]] =
        next ? region.inner.newer.values[band_at + n + i]
             : OnLine(region.inner.older, region.inner.newer, static_cast<int>(band_at + i), t);
  }
  const Eigen::VectorXd& u = integrator.u();
  for (int dof : inner_gamma) region.band_u[dof] = u[dof];
  inner.band->Apply(region.band_u, region.band_ku);
  for (size_t i = 0; i < inner_gamma.size(); ++i)
    region.load_values[i] = -region.band_ku[inner_gamma[i]];
}

}  // namespace hapticsim
