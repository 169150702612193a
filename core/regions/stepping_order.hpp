#pragma once
// The order a virtual-time run steps the asynchronous regions in: the substeps' order the error
// map has always measured, or the order hapticsimd's threads run (docs/regions.md, "Known: the
// virtual-time runs step another order than the threads").

#include <optional>
#include <string_view>

namespace hapticsim {

/**
 * kSubsteps: before each of the primary's substeps the secondaries step until they can supply Γ
 * at its end (AsyncRegions::AdvanceSecondariesTo), each reading the primary's band at most one
 * primary substep old. The default of every virtual-time run.
 *
 * kThreads: as hapticsimd's threads and RealTimeSchedule step them. Each region wakes once per
 * period and takes its period's substeps in a row; a secondary's wake is released ahead of its
 * period's start by ReleaseLeadsNs (1.25 inner periods at another rate, half a period at one
 * rate), so it reads the inner band as it was then, carried at most one inner substep on. On
 * time, the threads reproduce this order to round-off; where a secondary runs at another rate in
 * several substeps the two orders differ, and then this is the one the daemon's force has.
 */
enum class SteppingOrder { kSubsteps, kThreads };

/** "substeps" or "threads". */
constexpr std::string_view SteppingOrderName(SteppingOrder order) {
  return order == SteppingOrder::kThreads ? "threads" : "substeps";
}
/** The order a name names ("substeps", "threads"); nullopt for any other. */
constexpr std::optional<SteppingOrder> SteppingOrderNamed(std::string_view name) {
  if (name == "substeps") return SteppingOrder::kSubsteps;
  if (name == "threads") return SteppingOrder::kThreads;
  return std::nullopt;
}

}  // namespace hapticsim
