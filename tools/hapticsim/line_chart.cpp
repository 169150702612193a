#include "tools/hapticsim/line_chart.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "tools/hapticsim/svg_text.hpp"

namespace hapticsim::cli {

std::string LineChartSvg(const std::string& title, const std::string& x_label,
                         const std::string& y_label, const std::vector<double>& x,
                         const std::vector<ChartSeries>& series) {
  constexpr double kWidth = 760, kHeight = 300, kLeft = 70, kRight = 20, kTop = 30, kBottom = 45;
  const char* colours[] = {"#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e"};
  double x_min = x.empty() ? 0 : x.front(), x_max = x.empty() ? 1 : x.back();
  double y_min = 0, y_max = 0;
  for (const ChartSeries& s : series) {
    for (double v : s.y) {
      if (std::isfinite(v)) y_max = std::max(y_max, v), y_min = std::min(y_min, v);
    }
  }
  if (x_min > 0 && x_min < 0.05 * (x_max - x_min)) x_min = 0;  // an axis from 0, not 0.0004
  if (!(x_max > x_min)) x_max = x_min + 1;
  if (!(y_max > y_min)) y_max = y_min + 1;
  y_max *= 1.05;
  auto px = [&](double v) {
    return kLeft + (v - x_min) / (x_max - x_min) * (kWidth - kLeft - kRight);
  };
  auto py = [&](double v) {
    return kHeight - kBottom - (v - y_min) / (y_max - y_min) * (kHeight - kTop - kBottom);
  };
  std::ostringstream svg;
  svg << SvgChartOpening(kWidth, kHeight, kLeft, kRight, kTop, kBottom, title);
  for (int tick = 0; tick <= 4; ++tick) {
    const double yv = y_min + (y_max - y_min) * tick / 4, xv = x_min + (x_max - x_min) * tick / 4;
    svg << "<text x='" << kLeft - 6 << "' y='" << py(yv) + 4 << "' text-anchor='end'>"
        << SvgNumber(yv) << "</text>\n"
        << "<line x1='" << kLeft << "' x2='" << kWidth - kRight << "' y1='" << py(yv) << "' y2='"
        << py(yv) << "' stroke='#eee'/>\n"
        << "<text x='" << px(xv) << "' y='" << kHeight - kBottom + 16 << "' text-anchor='middle'>"
        << SvgNumber(xv) << "</text>\n";
  }
  svg << "<text x='" << (kLeft + kWidth - kRight) / 2 << "' y='" << kHeight - 8
      << "' text-anchor='middle'>" << SvgEscape(x_label) << "</text>\n"
      << "<text transform='translate(16," << (kTop + kHeight - kBottom) / 2
      << ") rotate(-90)' text-anchor='middle'>" << SvgEscape(y_label) << "</text>\n";
  for (std::size_t k = 0; k < series.size(); ++k) {
    const char* colour = colours[k % 5];
    svg << "<polyline fill='none' stroke='" << colour << "' stroke-width='1.5' points='";
    for (std::size_t i = 0; i < x.size() && i < series[k].y.size(); ++i) {
      if (std::isfinite(series[k].y[i])) svg << px(x[i]) << "," << py(series[k].y[i]) << " ";
    }
    svg << "'/>\n<text x='" << kWidth - kRight - 150 << "' y='" << kTop + 16 + 16 * k << "' fill='"
        << colour << "'>" << SvgEscape(series[k].name) << "</text>\n";
  }
  svg << "</svg>\n";
  return svg.str();
}

}  // namespace hapticsim::cli
