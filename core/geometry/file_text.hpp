#pragma once

#include <algorithm>
#include <cctype>
#include <sstream>
#include <string>
#include <string_view>

namespace hapticsim {

/** Whether `path` ends in `suffix` ("organ.NII.GZ" ends in ".nii.gz"): file types by name. */
inline bool EndsWithIgnoringCase(std::string path, std::string_view suffix) {
  std::transform(path.begin(), path.end(), path.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return path.size() >= suffix.size() &&
         path.compare(path.size() - suffix.size(), suffix.size(), suffix) == 0;
}

/** A number from a geometry file for a message: 9 significant digits, no trailing zeros. */
inline std::string FormatFileNumber(double value) {
  std::ostringstream text;
  text.precision(9);
  text << value;
  return text.str();
}

}  // namespace hapticsim
