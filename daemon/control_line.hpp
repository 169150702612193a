#pragma once

#include <optional>
#include <string>
#include <vector>

#include "hapticsim/command_t.hpp"

namespace hapticsim {

/**
 * The words `hapticsim ctl` sends over the control socket, one request a message:
 *
 *   set-error-target PERCENT                       SET_ERROR_TARGET
 *   pin PRIMARY_SIZE SECONDARY_LOD SECONDARY_HZ    PIN_CONFIGURATION
 *   release                                        RELEASE_CONFIGURATION
 *   reset                                          RESET
 *
 * Returns the command the line names (its fields are then checked by CheckCommand, as an LCM
 * command's are), or nothing with *error saying what is wrong with the line. Never throws.
 */
std::optional<command_t> ParseControlLine(const std::string& line, std::string* error);

/** The request line for `words` as typed after `hapticsim ctl`, joined by single spaces. */
std::string ControlLine(const std::vector<std::string>& words);

}  // namespace hapticsim
