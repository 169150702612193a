#pragma once

#include <cmath>
#include <cstdio>
#include <string>

namespace hapticsim::cli {

/** A number with 4 significant digits and its unit, e.g. Quantity(0.00293, "s") = "0.00293 s". */
inline std::string Quantity(double value, const char* unit) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.4g %s", value, unit);
  return buffer;
}

/** A duration in the most readable of s, ms, µs. */
inline std::string Duration(double seconds) {
  const double magnitude = std::abs(seconds);
  if (magnitude >= 1.0 || magnitude == 0.0) return Quantity(seconds, "s");
  if (magnitude >= 1e-3) return Quantity(seconds * 1e3, "ms");
  return Quantity(seconds * 1e6, "µs");
}

}  // namespace hapticsim::cli
