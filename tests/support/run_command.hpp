#pragma once

#include <string>
#include <vector>

namespace hapticsim::testing {

struct CommandResult {
  int exit_status = -1;
  std::string out;  ///< standard output
  std::string err;  ///< standard error
};

/** Runs a program (no shell) and collects its exit status and both output streams. */
CommandResult RunCommand(const std::vector<std::string>& argv);

}  // namespace hapticsim::testing
