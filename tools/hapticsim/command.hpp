#pragma once

#include <CLI/CLI.hpp>
#include <functional>

namespace hapticsim::cli {

/** Exit statuses shared by every subcommand. */
enum ExitStatus : int {
  kExitOk = 0,
  kExitInternalError = 1,
  kExitBadInput = 2,        ///< bad command line, scene file or value: the message names the key
  kExitUnstable = 3,        ///< the run was refused as unstable or diverged
  kExitLimitsExceeded = 4,  ///< device / soak: a --max-* limit or a check failed
};

/** A registered subcommand: its CLI11 app and what to run when it was chosen. */
struct Command {
  CLI::App* app = nullptr;
  std::function<int()> run;
};

Command AddSimulateCommand(CLI::App& parent);
Command AddStaticCommand(CLI::App& parent);
Command AddStabilityCommand(CLI::App& parent);
Command AddSceneCommand(CLI::App& parent);
Command AddSweepCommand(CLI::App& parent);
Command AddMapCommand(CLI::App& parent);
Command AddLookupCommand(CLI::App& parent);
Command AddAnalyzeCommand(CLI::App& parent);
Command AddDeviceCommand(CLI::App& parent);
Command AddLogCommand(CLI::App& parent);
Command AddStressCommand(CLI::App& parent);
Command AddBenchCommand(CLI::App& parent);
Command AddCtlCommand(CLI::App& parent);
Command AddViewCommand(CLI::App& parent);
/** argc/argv: soak runs itself again inside a private network namespace. */
Command AddSoakCommand(CLI::App& parent, int argc, char** argv);

}  // namespace hapticsim::cli
