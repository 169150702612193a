#include "tools/hapticsim/scatter_chart.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "tools/hapticsim/svg_text.hpp"

namespace hapticsim::cli {
namespace {

// A round tick step that divides [0, max] into at most `ticks` parts: 1, 2 or 5 × 10ⁿ.
double NiceStep(double max, int ticks) {
  const double raw = max / ticks, decade = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0, 10.0}) {
    if (m * decade >= raw) return m * decade;
  }
  return 10 * decade;
}

}  // namespace

std::string ParetoChartSvg(const std::string& title, const std::vector<ScatterPoint>& points,
                           double reference_cost, double threshold_percent) {
  constexpr double kWidth = 760, kHeight = 440, kLeft = 70, kRight = 20, kTop = 48, kBottom = 45;
  double x_max = reference_cost, y_max = threshold_percent;
  for (const ScatterPoint& p : points) {
    if (std::isfinite(p.cost)) x_max = std::max(x_max, p.cost);
    if (std::isfinite(p.error)) y_max = std::max(y_max, p.error);
  }
  const double x_step = NiceStep(x_max > 0 ? 1.05 * x_max : 1, 5);
  const double y_step = NiceStep(y_max > 0 ? 1.05 * y_max : 1, 5);
  x_max = x_step * std::ceil((x_max > 0 ? 1.05 * x_max : 1) / x_step);
  y_max = y_step * std::ceil((y_max > 0 ? 1.05 * y_max : 1) / y_step);
  auto px = [&](double v) { return kLeft + v / x_max * (kWidth - kLeft - kRight); };
  auto py = [&](double v) { return kHeight - kBottom - v / y_max * (kHeight - kTop - kBottom); };
  std::ostringstream svg;
  svg << SvgChartOpening(kWidth, kHeight, kLeft, kRight, kTop, kBottom, title);
  for (double yv = 0; yv <= y_max * (1 + 1e-9); yv += y_step) {
    svg << "<text x='" << kLeft - 6 << "' y='" << py(yv) + 4 << "' text-anchor='end'>"
        << SvgNumber(yv) << "</text>\n"
        << "<line x1='" << kLeft << "' x2='" << kWidth - kRight << "' y1='" << py(yv) << "' y2='"
        << py(yv) << "' stroke='#eee'/>\n";
  }
  for (double xv = 0; xv <= x_max * (1 + 1e-9); xv += x_step) {
    svg << "<text x='" << px(xv) << "' y='" << kHeight - kBottom + 16 << "' text-anchor='middle'>"
        << SvgNumber(xv) << "</text>\n";
  }
  svg << "<text x='" << (kLeft + kWidth - kRight) / 2 << "' y='" << kHeight - 8
      << "' text-anchor='middle'>compute per simulated ms (µs), all regions</text>\n"
      << "<text transform='translate(16," << (kTop + kHeight - kBottom) / 2
      << ") rotate(-90)' text-anchor='middle'>L2 force error against the reference (%)</text>\n";
  // The reference's cost and the perception threshold.
  svg << "<line x1='" << px(reference_cost) << "' x2='" << px(reference_cost) << "' y1='" << kTop
      << "' y2='" << kHeight - kBottom << "' stroke='#d62728' stroke-dasharray='6,4'/>\n"
      << "<text x='" << px(reference_cost) + 4 << "' y='" << kTop + 30
      << "' fill='#d62728'>full-resolution reference, " << SvgNumber(reference_cost)
      << " µs/ms</text>\n"
      << "<line x1='" << kLeft << "' x2='" << kWidth - kRight << "' y1='" << py(threshold_percent)
      << "' y2='" << py(threshold_percent) << "' stroke='#2ca02c' stroke-dasharray='6,4'/>\n"
      << "<text x='" << kLeft + 6 << "' y='" << py(threshold_percent) - 4 << "' fill='#2ca02c'>"
      << SvgNumber(threshold_percent) << " % (force JND)</text>\n";
  // The front as a staircase: from each front point across to the next one's cost, then down.
  std::vector<ScatterPoint> front;
  for (const ScatterPoint& p : points) {
    if (p.on_front) front.push_back(p);
  }
  std::sort(front.begin(), front.end(),
            [](const ScatterPoint& a, const ScatterPoint& b) { return a.cost < b.cost; });
  if (!front.empty()) {
    svg << "<polyline fill='none' stroke='#1f77b4' stroke-width='1.5' points='";
    for (size_t i = 0; i < front.size(); ++i) {
      if (i > 0) svg << px(front[i].cost) << "," << py(front[i - 1].error) << " ";
      svg << px(front[i].cost) << "," << py(front[i].error) << " ";
    }
    svg << "'/>\n";
  }
  for (const ScatterPoint& p : points) {
    if (!std::isfinite(p.cost) || !std::isfinite(p.error)) continue;
    svg << "<circle cx='" << px(p.cost) << "' cy='" << py(p.error) << "' r='"
        << (p.on_front ? 4.5 : 3) << "' fill='" << (p.on_front ? "#1f77b4" : "#aaa") << "'><title>"
        << SvgEscape(p.label) << ": " << SvgNumber(p.cost) << " µs/ms, " << SvgNumber(p.error)
        << " %</title></circle>\n";
  }
  // The legend: its own row under the title.
  svg << "<text x='" << kLeft << "' y='38' fill='#1f77b4'>● Pareto front (cheapest for its error)"
      << "</text><text x='" << kLeft + 250 << "' y='38' fill='#888'>● other configurations</text>\n"
      << "</svg>\n";
  return svg.str();
}

}  // namespace hapticsim::cli
