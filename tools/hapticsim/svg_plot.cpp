#include "tools/hapticsim/svg_plot.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <sstream>
#include <vector>

#include "core/error.hpp"
#include "tools/hapticsim/format.hpp"

namespace hapticsim::cli {
namespace {

constexpr double kWidth = 760, kPanelHeight = 220, kLeft = 70, kRight = 20, kTop = 40, kGap = 50;

// "Nice" tick spacing: 1, 2 or 5 × 10ᵏ giving about `target` ticks over the span.
double TickStep(double span, int target) {
  const double raw = span / target;
  const double power = std::pow(10.0, std::floor(std::log10(raw)));
  for (double factor : {1.0, 2.0, 5.0, 10.0}) {
    if (factor * power >= raw) return factor * power;
  }
  return 10 * power;
}

std::string Number(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%g", std::abs(value) < 1e-12 ? 0.0 : value);
  return buffer;
}

struct Series {
  std::function<double(const ForceSample&)> value;
  const char* colour;
  const char* label;
};

void Panel(std::ostream& svg, double top, const std::vector<ForceSample>& samples, double t_end,
           const std::vector<Series>& series, const char* y_label) {
  double lo = 0, hi = 0;
  for (const auto& s : series) {
    for (const auto& sample : samples) {
      lo = std::min(lo, s.value(sample));
      hi = std::max(hi, s.value(sample));
    }
  }
  if (hi - lo < 1e-300) hi = lo + 1;
  const double pad = 0.05 * (hi - lo);
  lo -= pad;
  hi += pad;
  const double plot_w = kWidth - kLeft - kRight;
  auto x_of = [&](double t) { return kLeft + plot_w * t / t_end; };
  auto y_of = [&](double v) { return top + kPanelHeight * (hi - v) / (hi - lo); };

  svg << "<rect x='" << kLeft << "' y='" << top << "' width='" << plot_w << "' height='"
      << kPanelHeight << "' fill='none' stroke='#444'/>\n";
  const double y_step = TickStep(hi - lo, 5);
  for (double v = std::ceil(lo / y_step) * y_step; v <= hi; v += y_step) {
    svg << "<line x1='" << kLeft << "' x2='" << kLeft + plot_w << "' y1='" << y_of(v) << "' y2='"
        << y_of(v) << "' stroke='#ddd'/><text x='" << kLeft - 6 << "' y='" << y_of(v) + 4
        << "' text-anchor='end'>" << Number(v) << "</text>\n";
  }
  const double t_step = TickStep(t_end, 8);
  for (double t = 0; t <= t_end * (1 + 1e-9); t += t_step) {
    svg << "<line x1='" << x_of(t) << "' x2='" << x_of(t) << "' y1='" << top << "' y2='"
        << top + kPanelHeight << "' stroke='#eee'/><text x='" << x_of(t) << "' y='"
        << top + kPanelHeight + 16 << "' text-anchor='middle'>" << Number(t) << "</text>\n";
  }
  svg << "<text transform='translate(16," << top + kPanelHeight / 2
      << ") rotate(-90)' text-anchor='middle'>" << y_label << "</text>\n";
  double legend_x = kLeft + 10;
  for (const auto& s : series) {
    svg << "<polyline fill='none' stroke='" << s.colour << "' stroke-width='1.6' points='";
    const size_t stride = std::max<size_t>(1, samples.size() / 2000);
    for (size_t i = 0; i < samples.size(); i += stride) {
      svg << x_of(samples[i].t_s) << ',' << y_of(s.value(samples[i])) << ' ';
    }
    svg << "'/>\n<text x='" << legend_x << "' y='" << top + 16 << "' fill='" << s.colour << "'>"
        << s.label << "</text>\n";
    legend_x += 110;
  }
}

}  // namespace

void WriteForcePlot(const std::string& path, const TrialResult& result, const Scene& scene) {
  const auto& samples = result.samples;
  const double t_end = std::max(samples.back().t_s, 1e-9);
  std::ostringstream svg;
  const double height = kTop + 2 * kPanelHeight + kGap + 40;
  svg << "<svg xmlns='http://www.w3.org/2000/svg' width='" << kWidth << "' height='" << height
      << "' font-family='sans-serif' font-size='12'>\n<rect width='100%' height='100%' "
         "fill='white'/>\n<text x='"
      << kLeft << "' y='22' font-size='14'>Force on the user: " << ObjectDescription(scene) << ", "
      << WaveformName(scene.input.waveform) << " of " << Number(scene.input.amplitude_m) << " m at "
      << Number(scene.input.frequency_hz) << " Hz";
  if (scene.materials.empty()) {  // else each label's own, in its [[material]] table
    svg << ", E " << Number(scene.material.youngs_modulus_pa) << " Pa, ν "
        << Number(scene.material.poisson_ratio);
  }
  svg << "</text>\n";
  Panel(svg, kTop, samples, t_end,
        {{[](const ForceSample& s) { return s.feedback_force_n[0]; }, "#1b9e77", "force x"},
         {[](const ForceSample& s) { return s.feedback_force_n[1]; }, "#7570b3", "force y"},
         {[](const ForceSample& s) { return s.feedback_force_n[2]; }, "#d95f02", "force z"}},
        "force on the user (N)");
  const double top2 = kTop + kPanelHeight + kGap;
  Panel(svg, top2, samples, t_end,
        {{[](const ForceSample& s) { return s.contact_displacement_m[2]; }, "#333",
          "contact depth z"}},
        "contact depth (m)");
  svg << "<text x='" << kLeft + (kWidth - kLeft - kRight) / 2 << "' y='" << height - 6
      << "' text-anchor='middle'>time (s)</text>\n</svg>\n";

  std::ofstream out(path);
  HAPTICSIM_THROW_UNLESS(out.good(), "cannot write the plot to " + path +
                                         ": check that the folder exists and is writable");
  out << svg.str();
}

}  // namespace hapticsim::cli
