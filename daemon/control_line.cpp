#include "daemon/control_line.hpp"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <sstream>
#include <vector>

#include "ipc/service_socket.hpp"

namespace hapticsim {
namespace {

constexpr const char* kUsage =
    "use one of: set-error-target PERCENT | pin PRIMARY_SIZE SECONDARY_LOD SECONDARY_HZ | "
    "release | reset";

// A whole word as a number; nothing when any of it is not one (no "5%", no "3x").
std::optional<double> Number(const std::string& word) {
  if (word.empty() || word.size() > 32) return std::nullopt;
  errno = 0;
  char* end = nullptr;
  const double value = std::strtod(word.c_str(), &end);
  if (errno != 0 || end != word.c_str() + word.size() || !std::isfinite(value)) {
    return std::nullopt;
  }
  return value;
}

// A whole number that an int32 field holds exactly; nothing otherwise.
std::optional<std::int32_t> WholeNumber(const std::string& word) {
  const std::optional<double> value = Number(word);
  if (!value || *value != std::floor(*value) || *value < -2147483648.0 || *value > 2147483647.0) {
    return std::nullopt;
  }
  return static_cast<std::int32_t>(*value);
}

// A word of the requester's, as it may be shown in an answer or the log: at most 40 characters,
// printable ones only (no terminal escapes).
std::string Shown(const std::string& word) { return shm::Printable(word.substr(0, 40)); }

}  // namespace

std::optional<command_t> ParseControlLine(const std::string& line, std::string* error) {
  std::vector<std::string> words;
  std::istringstream in(line);
  for (std::string word; in >> word;) words.push_back(word);
  command_t command{};
  auto fail = [&](const std::string& why) {
    *error = why;
    return std::nullopt;
  };
  if (words.empty()) return fail(std::string("an empty request: ") + kUsage);
  const std::string& verb = words[0];
  const std::size_t arguments = words.size() - 1;
  if (verb == "set-error-target") {
    if (arguments != 1) return fail("set-error-target takes one number: the target, %");
    const std::optional<double> target = Number(words[1]);
    if (!target) return fail("set-error-target " + Shown(words[1]) + ": not a number");
    command.command = command_t::SET_ERROR_TARGET;
    command.error_target_percent = *target;
  } else if (verb == "pin") {
    if (arguments != 3) {
      return fail("pin takes three numbers: primary_size, secondary_lod, secondary rate in Hz");
    }
    const std::optional<std::int32_t> size = WholeNumber(words[1]), lod = WholeNumber(words[2]);
    const std::optional<double> rate = Number(words[3]);
    if (!size || !lod || !rate) {
      return fail("pin " + Shown(words[1]) + " " + Shown(words[2]) + " " + Shown(words[3]) +
                  ": primary_size and secondary_lod must be whole numbers, the rate a number");
    }
    command.command = command_t::PIN_CONFIGURATION;
    command.primary_size = *size;
    command.secondary_lod = *lod;
    command.secondary_rate_hz = *rate;
  } else if (verb == "release" || verb == "reset") {
    if (arguments != 0) return fail(verb + " takes nothing after it");
    command.command = verb == "release" ? std::int32_t{command_t::RELEASE_CONFIGURATION}
                                        : std::int32_t{command_t::RESET};
  } else {
    return fail("unknown request \"" + Shown(verb) + "\": " + kUsage);
  }
  return command;
}

std::string ControlLine(const std::vector<std::string>& words) {
  std::string line;
  for (const std::string& word : words) line += (line.empty() ? "" : " ") + word;
  return line;
}

}  // namespace hapticsim
