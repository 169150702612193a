#pragma once

#include <string>
#include <vector>

#include "rt/deadline_monitor.hpp"
#include "daemon/haptic_loop.hpp"
#include "daemon/input_counters.hpp"
#include "daemon/supervisor.hpp"
#include "hapticsim/status_t.hpp"

namespace hapticsim {

/**
 * The status message of the running daemon: the active configuration and its error, the input
 * counters, and each region's schedule and deadline statistics (`snapshots`, one per region).
 */
status_t MakeStatus(const HapticLoop& loop, const std::vector<DeadlineSnapshot>& snapshots,
                    const SupervisorDecision& decision, double target, bool pinned,
                    const std::string& map_path, const InputCounters* counters);

}  // namespace hapticsim
