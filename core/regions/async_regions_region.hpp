#pragma once
// AsyncRegions' per-region state, shared by the files that implement AsyncRegions
// (core/regions/async_regions.cpp: the steps and the schedule; core/regions/region_state_transfer.cpp: a state
// carried between configurations). Not part of the interface: include core/regions/async_regions.hpp.

#include <Eigen/Core>
#include <atomic>
#include <cstdint>
#include <memory>
#include <vector>

#include "core/regions/async_regions.hpp"
#include "core/regions/boundary_channel.hpp"
#include "core/regions/element_set_stiffness.hpp"
#include "core/fem/region_integrator.hpp"
#include "core/regions/region_partition.hpp"
#include "rt/seqlock_array.hpp"

namespace hapticsim {

// Everything one region's thread touches. The link to the next region outwards (if any) is
// stored here: `inward` is written by the outer region, `outward` by this one.
struct AsyncRegions::Region {
  RegionSchedule schedule;
  std::int64_t period_ticks = 0;
  std::int64_t state_ticks = 0;
  const RegionDofs* dofs = nullptr;
  std::unique_ptr<RegionIntegrator> integrator;
  std::vector<double> prescribed_values;  // [contact (primary only)] [fixed] [outer Γ]
  size_t outer_offset = 0;
  double compute_s = 0;

  // Link with the region outwards: this region is its inner side.
  std::unique_ptr<BoundaryChannel> inward;    // outer → this: outer Γ displacements
  std::unique_ptr<BoundaryChannel> outward;   // this → outer: band displacements or Γ forces,
                                              // then the band's next step
  std::unique_ptr<ElementSetStiffness> band;  // this region's elements next to its outer Γ
  std::vector<int> band_layer;                // their DOFs off the outer Γ
  // With either exchange the band is published as this region's next step will put it
  // (RegionIntegrator::NextBeforeLoads, for an outer region with steps as long, a thread that
  // takes a later substep of its period before this region has taken its own: ReadInnerLoads),
  // after the band as it is (displacement exchange) or the forces on Γ (force exchange). Each
  // band DOF's place in this region's owned DOFs; −1 for a prescribed one (a support, the
  // contact), which is held.
  std::vector<int> band_layer_slot;
  BoundaryChannel::ReadPair outer;     // Γ from the outer region, read by this region's thread
  std::vector<double> outward_values;  // written by this region's thread

  // Link with the region inwards: this region is its outer side (owns that Γ).
  BoundaryChannel::ReadPair inner;  // the inner region's side, read by this region's thread
  std::vector<double> inward_values, load_values;
  Eigen::VectorXd band_u, band_ku;  // for evaluating the inner region's band

  // The energy balance (docs/regions.md, "Passive interfaces"), J since Reset. Written by
  // this region's thread; the *_published copies for the neighbours' threads to read.
  double input_work = 0;                          // the contact's work (primary)
  double damping_dissipated = 0;                  // material damping
  double port_refused = 0;                        // work the port limits kept out (PortWorkLimits)
  std::atomic<double> energy_published{0};        // its discrete energy at its last step's start
  std::atomic<double> state_energy_published{0};  // its StateEnergy then (the runaway watch)
  std::atomic<double> input_work_published{0}, damping_published{0};  // … and those sums
  // The largest port allowance each side has used and energy it has had since Reset, for the
  // bound the port limits guarantee (EnergyAccount::backlog_bound_j).
  double inward_allowance_peak = 0, outward_allowance_peak = 0, energy_peak = 0;
  // In lock-step (InwardPortLimit) the load is not limited: the largest work it did so, J.
  double lockstep_load_peak = 0;
  bool lockstep_step = false;                 // this step's load went unlimited
  std::int64_t no_lockstep_before_ticks = 0;  // after a skip: its u⁻ is older than its Γ
  // As the inner side: the end tick of its latest step whose outer Γ did not follow the outer
  // region's snapshot at that time (held for a late outer region, or port-limited). Stored
  // before the band is published (release), read after it (acquire).
  std::atomic<std::int64_t> last_inexact_follow_ticks{INT64_MIN};
  // Its steps whose outer Γ the outer region had not published up to their end
  // (held_boundary_steps).
  std::atomic<std::int64_t> held_boundary_steps{0};
  // As the inner side of the link outwards:
  double outer_gamma_work = 0;  // work done on this region by moving its outer Γ
  double outward_taken = 0;     // what its controller took out for that link
  std::atomic<double> outer_gamma_work_published{0}, outward_taken_published{0};
  // As the outer side of the link inwards, which keeps the link's observer:
  double inner_gamma_load_work = 0;  // work done on this region by the inner region's load
  double inward_taken = 0;           // what its controller took out for that link
  double excess = 0;                 // the observer (ObserveInwardLink)
  double inner_work_seen = 0, inner_taken_seen = 0;  // the inner side's, counted in it
  double unmet = 0;  // what its last step was asked to take out and could not
  std::atomic<double> unmet_published{0}, inner_taken_seen_published{0};
  // The observer less the inner side's sums it has counted: the inner side adds its own sums
  // (known exactly) to this one number to see the observer as it would be (InwardPortLimit).
  std::atomic<double> excess_base_published{0};

  // Its part of the object's surface (core/regions/region_surface.cpp): the owned DOFs the surface needs,
  // published after a step when a reader has asked since the last publication.
  std::vector<int> surface_dofs;
  std::unique_ptr<SeqlockArray> surface;
  std::uint64_t surface_request_served = 0;  // this region's thread
  std::atomic<std::uint64_t> surface_served{0};
};

}  // namespace hapticsim
