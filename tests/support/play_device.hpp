#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <functional>
#include <thread>
#include <vector>

#include "daemon/haptic_loop.hpp"

namespace hapticsim::testing {

/**
 * Plays a device at 1 kHz on absolute sleeps into a running HapticLoop: `tip(n)` for n = 0, 1, …
 * (sent with seq first_seq + n) for at least `periods` periods and until `done()`; returns every
 * force the loop handed over meanwhile (and in the 5 ms after).
 */
inline std::vector<ForceRecord> PlayDevice(
    HapticLoop& loop, int periods, const std::function<std::array<double, 3>(int)>& tip,
    const std::function<bool()>& done = [] { return true; }, std::int64_t first_seq = 0) {
  std::vector<ForceRecord> forces;
  forces.reserve(static_cast<size_t>(periods) + 100);
  auto next = std::chrono::steady_clock::now();
  ForceRecord record;
  for (int n = 0; n < periods || !done(); ++n) {
    loop.OfferInput(DeviceSample{first_seq + n, HapticLoop::NowNs(), tip(n), false});
    while (loop.forces().Pop(&record)) forces.push_back(record);
    next += std::chrono::milliseconds(1);
    std::this_thread::sleep_until(next);
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(5));
  while (loop.forces().Pop(&record)) forces.push_back(record);
  return forces;
}

}  // namespace hapticsim::testing
