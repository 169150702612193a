#pragma once

#include <string>
#include <vector>

namespace hapticsim::cli {

/** One line of a chart: its name and its y values (one per x). */
struct ChartSeries {
  std::string name;
  std::vector<double> y;
};

/**
 * A self-contained SVG line chart (no scripts, no external files) for reports: x against any
 * number of series sharing one y axis, with labelled axes and a legend.
 */
std::string LineChartSvg(const std::string& title, const std::string& x_label,
                         const std::string& y_label, const std::vector<double>& x,
                         const std::vector<ChartSeries>& series);

}  // namespace hapticsim::cli
