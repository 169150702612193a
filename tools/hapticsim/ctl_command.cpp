// hapticsim ctl: a command to the running daemon over its control socket (control.socket), the
// one channel state-changing commands come from by default. The daemon checks who sent it.
// With --lcm, the command goes on the LCM bus instead, signed with a key the daemon shares
// (lcm.accept_commands, lcm.command_key_file); --make-key makes such a key.
#include <iostream>
#include <lcm/lcm-cpp.hpp>
#include <memory>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "daemon/control_line.hpp"
#include "daemon/daemon_config.hpp"
#include "ipc/command_signature.hpp"
#include "ipc/control_client.hpp"
#include "ipc/lcm_start.hpp"
#include "tools/hapticsim/command.hpp"

namespace hapticsim::cli {
namespace {

struct CtlOptions {
  std::string socket = shm::kDefaultControlSocket;
  std::vector<std::string> request;
  double timeout_s = 5;
  bool lcm = false;
  std::string lcm_url = DaemonConfig{}.lcm_url;
  std::string channel = DaemonConfig{}.command_channel;
  std::string key_file;
  std::string make_key;
};

int MakeKey(const std::string& path) {
  WriteNewCommandKey(path);
  std::cout << "wrote a new 256-bit key to " << path
            << " (mode 0600). For the daemon: lcm.accept_commands = true and "
               "lcm.command_key_file = \""
            << path << "\"; for senders: hapticsim ctl --lcm --key-file " << path << " REQUEST\n";
  return kExitOk;
}

int SendSignedOnLcm(const CtlOptions& o, const std::string& line) {
  if (o.key_file.empty()) {
    throw Error(
        "ctl --lcm needs --key-file: the daemon takes only commands signed with the key "
        "in its lcm.command_key_file");
  }
  const bool bus = o.lcm_url.rfind("udpm://", 0) == 0 || o.lcm_url.rfind("tcpq://", 0) == 0;
  if (const std::string problem = LcmUrlProblem(o.lcm_url, false); !bus || !problem.empty()) {
    throw Error("ctl --lcm-url " + o.lcm_url +
                ": hapticsim ctl sends on a udpm:// or tcpq:// bus on this host only" +
                (problem.empty() ? "" : " (" + problem.substr(0, problem.find(": keep it")) + ")"));
  }
  std::string error;
  std::optional<command_t> command = ParseControlLine(line, &error);
  if (!command) throw Error("ctl: " + error);
  const CommandKey key = ReadCommandKey(o.key_file);
  lcm::LCM lcm(o.lcm_url);
  command->utime = CommandClockUs();  // stamped last: the daemon takes it within 2 s
  SignCommand(&*command, o.channel, key);
  if (!lcm.good() || lcm.publish(o.channel, &*command) != 0) {
    throw Error("ctl: LCM could not send on " + o.lcm_url +
                " (for udpm:// the interface needs a multicast route: " + kLcmLoopbackRoute + ")");
  }
  std::cout << "sent, signed, on " << o.channel
            << ". LCM carries no answer: the daemon's status counts a refusal in "
               "commands_refused and its log says why\n";
  return kExitOk;
}

int RunCtl(const CtlOptions& o) {
  if (!o.make_key.empty()) return MakeKey(o.make_key);
  if (o.request.empty()) {
    throw Error(
        "ctl: name a request (set-error-target, pin, release, reset; see --help), or "
        "--make-key FILE");
  }
  const std::string line = ControlLine(o.request);
  if (o.lcm) return SendSignedOnLcm(o, line);
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
      "  pin PRIMARY_SIZE SECONDARY_LOD SECONDARY_HZ  hold this configuration (checked first)\n"
      "  release                                      choose freely again\n"
      "  reset                                        restart the simulation from rest\n"
      "With --lcm --key-file FILE the command goes on LCM instead, signed with the key the "
      "daemon shares (lcm.command_key_file); --make-key FILE makes such a key.\n"
      "Exit status 0 when the daemon answers ok (--lcm: when the command was sent), 2 when it "
      "refuses or cannot be reached.");
  app->add_option("--socket", options->socket, "The daemon's control socket (control.socket)")
      ->capture_default_str();
  app->add_option("--timeout", options->timeout_s, "Seconds to wait for the answer")
      ->capture_default_str()
      ->check(CLI::Range(0.1, 60.0));
  app->add_flag("--lcm", options->lcm,
                "Send the command on LCM, signed (needs --key-file; no answer comes back)");
  app->add_option("--key-file", options->key_file,
                  "The key shared with the daemon's lcm.command_key_file (64 hex digits)");
  app->add_option("--lcm-url", options->lcm_url, "The LCM bus (this host only)")
      ->capture_default_str();
  app->add_option("--channel", options->channel, "The daemon's lcm.command_channel")
      ->capture_default_str();
  app->add_option("--make-key", options->make_key,
                  "Make a new random key file (mode 0600) and exit; never overwrites one");
  app->add_option("request", options->request, "The request and its numbers")->expected(1, 4);
  return {app, [options] { return RunCtl(*options); }};
}

}  // namespace hapticsim::cli
