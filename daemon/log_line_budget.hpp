#pragma once

#include <cstdint>

namespace hapticsim {

/**
 * Whether a repeated warning may be said again at `now_ns` (CLOCK_MONOTONIC): at most
 * log.max_lines_per_s such lines a second, counted from the last one, said at `last_line_ns`.
 * What is not said is still counted (the status message carries the counts).
 */
inline bool LineDue(std::int64_t now_ns, std::int64_t last_line_ns, double max_lines_per_s) {
  return (now_ns - last_line_ns) * 1e-9 >= 1.0 / max_lines_per_s;
}

}  // namespace hapticsim
