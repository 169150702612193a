// hapticsim: the command-line front end of the simulation core.
//
//   hapticsim simulate [--out forces.csv] [--plot forces.svg]   reference run of a scene
//   hapticsim static                                             static contact reaction
//   hapticsim stability                                          critical time step
//   hapticsim scene                                              the effective scene as TOML
//   hapticsim sweep [--grid paper|quick|scene|FILE] [--out MAP]  make an error map
//   hapticsim map info|export|merge                              inspect and join map files
//   hapticsim lookup MAP --set key=value                         the run-time error lookup
//   hapticsim analyze MAP [--report report.html]                 Table I and the HTML report
//   hapticsim device [--transport lcm|shm] [--input press|sine|walk|replay]   simulated device
//   hapticsim soak [--duration 60] [--json]                      daemon + device, checked
//   hapticsim ctl reset | release | pin 3 2 600 | set-error-target 5    a command to the daemon
//   hapticsim log SESSION.lcmlog [--csv out.csv]                 a recorded session
//   hapticsim view [--port 8765]                                 live view in the browser
//
// Exit status: 0 success, 2 bad input (the message names the key), 3 unstable or diverged,
// 4 a device or soak limit exceeded, 1 anything else.
#include <iostream>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/errormap/error_sweep.hpp"
#include "tools/hapticsim/command.hpp"

int main(int argc, char** argv) {
  using namespace hapticsim::cli;
  CLI::App app{
      "hapticsim: force feedback from a deforming soft-tissue model (linear hexahedral FEM),\n"
      "with the error of that force. Units are SI throughout. Run a subcommand with --help.",
      "hapticsim"};
  app.set_version_flag("--version", hapticsim::CodeVersion());
  app.require_subcommand(1);
  app.set_help_all_flag("--help-all", "Help for every subcommand");
  const std::vector<Command> commands{AddSimulateCommand(app),  AddStaticCommand(app),
                                      AddStabilityCommand(app), AddSceneCommand(app),
                                      AddSweepCommand(app),     AddMapCommand(app),
                                      AddLookupCommand(app),    AddAnalyzeCommand(app),
                                      AddDeviceCommand(app),    AddSoakCommand(app, argc, argv),
                                      AddLogCommand(app),       AddStressCommand(app),
                                      AddBenchCommand(app),     AddCtlCommand(app),
                                      AddViewCommand(app)};
  if (argc > 1 && argv[1][0] != '-') {
    const std::string chosen = argv[1];
    bool known = false;
    std::string names;
    for (const Command& command : commands) {
      known = known || command.app->get_name() == chosen;
      names += (names.empty() ? "" : ", ") + command.app->get_name();
    }
    if (!known) {
      std::cerr << "hapticsim: error: unknown subcommand '" << chosen << "'; choose one of "
                << names << " (see hapticsim --help)\n";
      return kExitBadInput;
    }
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return kExitBadInput;
  }
  try {
    for (const Command& command : commands) {
      if (command.app->parsed()) return command.run();
    }
  } catch (const hapticsim::Error& e) {
    std::cerr << "hapticsim: error: " << e.what() << "\n";
    return kExitBadInput;
  } catch (const std::exception& e) {
    std::cerr << "hapticsim: internal error: " << e.what() << "\n";
    return kExitInternalError;
  }
  return kExitInternalError;
}
