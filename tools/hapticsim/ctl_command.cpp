// hapticsim ctl: a command to the running daemon over its control socket (control.socket), the
// one channel state-changing commands come from by default. The daemon checks who sent it.
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "ipc/control_client.hpp"
#include "tools/hapticsim/command.hpp"

namespace hapticsim::cli {
namespace {

struct CtlOptions {
  std::string socket = shm::kDefaultControlSocket;
  std::vector<std::string> request;
  double timeout_s = 5;
};

int RunCtl(const CtlOptions& o) {
  std::string line;
  for (const std::string& word : o.request) line += (line.empty() ? "" : " ") + word;
  const std::string answer =
      shm::SendControlRequest(o.socket, line, static_cast<int>(o.timeout_s * 1000));
  std::cout << answer << "\n";
  return answer.rfind("ok:", 0) == 0 ? kExitOk : kExitBadInput;
}

}  // namespace

Command AddCtlCommand(CLI::App& parent) {
  auto options = std::make_shared<CtlOptions>();
  CLI::App* app = parent.add_subcommand(
      "ctl",
      "Send a command to the running hapticsimd over its control socket (root, the daemon's "
      "user and control.group only) and print its answer. Requests:\n"
      "  set-error-target PERCENT                     the worst force error allowed, %\n"
      "  pin PRIMARY_SIZE SECONDARY_LOD SECONDARY_HZ  hold this configuration (verified first)\n"
      "  release                                      choose freely again\n"
      "  reset                                        restart the simulation from rest\n"
      "Exit status 0 when the daemon answers ok, 2 when it refuses or cannot be reached.");
  app->add_option("--socket", options->socket, "The daemon's control socket (control.socket)")
      ->capture_default_str();
  app->add_option("--timeout", options->timeout_s, "Seconds to wait for the answer")
      ->capture_default_str()
      ->check(CLI::Range(0.1, 60.0));
  app->add_option("request", options->request, "The request and its numbers")
      ->required()
      ->expected(1, 4);
  return {app, [options] { return RunCtl(*options); }};
}

}  // namespace hapticsim::cli
