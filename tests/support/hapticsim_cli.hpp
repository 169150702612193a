#pragma once

// Running the hapticsim binary from a test, as a user would.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "tests/support/run_command.hpp"

namespace hapticsim::testing {

/** hapticsim with these arguments (HAPTICSIM_CLI_PATH is set by the test's CMake target). */
inline CommandResult Hapticsim(std::vector<std::string> args) {
  args.insert(args.begin(), HAPTICSIM_CLI_PATH);
  return RunCommand(args);
}

/** The JSON a successful command printed (a failed one fails the test with its stderr). */
inline nlohmann::json Json(const CommandResult& result) {
  EXPECT_EQ(result.exit_status, 0) << result.err;
  return nlohmann::json::parse(result.out);
}

}  // namespace hapticsim::testing
