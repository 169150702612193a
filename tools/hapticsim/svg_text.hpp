#pragma once
// Text inside the SVG charts hapticsim writes: numbers short enough for a tick, and any string
// made safe for an element's content.

#include <cstdio>
#include <string>

namespace hapticsim::cli {

/** Four significant digits: "129.2", "0.0004", "1.5e+04". */
inline std::string SvgNumber(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.4g", v);
  return text;
}

/** `s` with <, > and & escaped. */
inline std::string SvgEscape(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '<')
      out += "&lt;";
    else if (c == '>')
      out += "&gt;";
    else if (c == '&')
      out += "&amp;";
    else
      out += c;
  }
  return out;
}

/** A chart's opening: the svg element, its title, and the frame of its plot area. */
inline std::string SvgChartOpening(double width, double height, double left, double right,
                                   double top, double bottom, const std::string& title) {
  std::string out =
      "<svg xmlns='http://www.w3.org/2000/svg' width='" + SvgNumber(width) + "' height='" +
      SvgNumber(height) + "' font-family='sans-serif' font-size='12'>\n<text x='" +
      SvgNumber(left) + "' y='18' font-size='14'>" + SvgEscape(title) + "</text>\n<rect x='" +
      SvgNumber(left) + "' y='" + SvgNumber(top) + "' width='" + SvgNumber(width - left - right) +
      "' height='" + SvgNumber(height - top - bottom) + "' fill='none' stroke='#888'/>\n";
  return out;
}

}  // namespace hapticsim::cli
