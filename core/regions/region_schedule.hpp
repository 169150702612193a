#pragma once

#include <memory>
#include <vector>

#include "core/regions/element_set_stiffness.hpp"
#include "core/regions/region_partition.hpp"
#include "core/scene/scene.hpp"
#include "core/fem/stability_estimate.hpp"

namespace hapticsim {

/** One region's schedule: its rate and how many substeps its stability limit requires. */
struct RegionSchedule {
  double rate_hz = 0;
  int substeps = 1;
  StabilityEstimate alone;  ///< the region's own limit with its boundary held
};

/**
 * The regions' schedules (AsyncRegions): the primary at the primary rate (1/solver.dt), the first
 * secondary shell at adaptivity.secondary_rate, further shells at adaptivity.outer_rate, each
 * rounded to whole hertz; each region with the fewest substeps that keep its step at most
 * `substep_safety` of its own critical step, and neighbours at one rate in lock-step.
 *
 * bands[a]: region a's elements next to its outer Γ (none for the outermost). With the
 * displacement exchange, and at its inner neighbour's rate with either, a region evaluates its
 * inner neighbour's band on its own Γ within its step, so that band's stiffness counts in its
 * own limit.
 *
 * primary_spring_omega2_per_s2: k/m of a contact spring on the primary's lightest loaded node
 * (a stroke's proxy, 1/s²; 0 for a driven contact node). It adds at most that to the primary's
 * ω² (positive semi-definite, of norm ≤ k/m), so the primary's limit is 2 / √(ω² + k/m).
 */
std::vector<RegionSchedule> ScheduleRegions(
    const RegionPartition& partition, const Scene& scene,
    const std::vector<std::unique_ptr<ElementSetStiffness>>& bands, bool displacement_coupling,
    double substep_safety, double primary_spring_omega2_per_s2 = 0);

}  // namespace hapticsim
