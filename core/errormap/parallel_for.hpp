#pragma once

#include <atomic>
#include <cstddef>
#include <functional>

namespace hapticsim {

/**
 * Runs fn(i) for every i in [0, n) on `jobs` threads (at least one), each taking the next i
 * as it finishes one; the calling thread calls `tick` (when set) every `tick_interval_s`
 * meanwhile, for progress. Stops taking new i once `stop` (when set) is true. The first exception
 * a call throws stops the others from taking more, and is rethrown here once all have ended.
 */
void ParallelFor(std::size_t n, int jobs, const std::atomic<bool>* stop,
                 const std::function<void(std::size_t)>& fn, const std::function<void()>& tick,
                 double tick_interval_s);

}  // namespace hapticsim
