#pragma once

#include <string>
#include <vector>

namespace hapticsim::cli {

/** One configuration on a run-time-against-error chart. */
struct ScatterPoint {
  double cost = 0;        ///< x: compute cost, µs per simulated ms
  double error = 0;       ///< y: force error, %
  bool on_front = false;  ///< on the Pareto front (drawn in colour, joined)
  std::string label;      ///< shown on hover
};

/**
 * A self-contained SVG scatter chart (no scripts, no external files): every configuration's
 * cost against its error, the Pareto front joined as a staircase, the full-resolution
 * reference's cost as a vertical line and a perception threshold as a horizontal one.
 */
std::string ParetoChartSvg(const std::string& title, const std::vector<ScatterPoint>& points,
                           double reference_cost, double threshold_percent);

}  // namespace hapticsim::cli
