// hapticsim view: a live picture of a running hapticsimd in the browser. It listens to the
// daemon's LCM messages (device input, force, status, deformed surface) and serves a page on
// 127.0.0.1 that draws them with three.js; see docs/simulator.md, "A live view".
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <nlohmann/json.hpp>
#include <thread>

#include "core/error.hpp"
#include "device/device_link.hpp"
#include "tools/hapticsim/command.hpp"
#include "tools/view/view_feed.hpp"
#include "tools/view/view_server.hpp"

extern char** environ;

namespace hapticsim::cli {
namespace {

struct ViewOptions {
  std::string lcm_url = device::kHostLocalLcmUrl;
  view::FeedChannels channels;
  view::ServerSettings server;
  std::string open = "auto";
};

std::atomic<bool> g_stop{false};
void OnStopSignal(int) { g_stop = true; }

// Starts the desktop's browser on the page (xdg-open), without waiting for it.
void OpenBrowser(const std::string& url) {
  const char* argv[] = {"xdg-open", url.c_str(), nullptr};
  pid_t pid = 0;
  if (posix_spawnp(&pid, "xdg-open", nullptr, nullptr, const_cast<char**>(argv), environ) != 0) {
    std::cerr << "hapticsim view: could not run xdg-open; open " << url << " yourself\n";
    return;
  }
  std::thread([pid] { waitpid(pid, nullptr, 0); }).detach();
}

int Run(const ViewOptions& o) {
  if (o.open != "auto" && o.open != "yes" && o.open != "no") {
    throw Error("--open " + o.open + ": use auto, yes or no");
  }
  const view::FeedChannels& channels = o.channels;
  view::ServerSettings settings = o.server;
  settings.hello_json = nlohmann::json{{"type", "hello"},
                                       {"lcm_url", o.lcm_url},
                                       {"channels",
                                        {{"device", channels.device},
                                         {"force", channels.force},
                                         {"status", channels.status},
                                         {"deformation", channels.deformation}}}}
                            .dump();
  // The port first: a command line it refuses never starts LCM.
  view::ViewServer server(settings);
  view::ViewFeed feed(o.lcm_url, channels);
  const std::string url = "http://127.0.0.1:" + std::to_string(server.port()) + "/";
  std::cout << "hapticsim view: serving " << url << " (listening to " << o.lcm_url
            << "); Ctrl-C stops" << std::endl;
  const bool desktop = std::getenv("DISPLAY") || std::getenv("WAYLAND_DISPLAY");
  if (o.open == "yes" || (o.open == "auto" && desktop)) OpenBrowser(url);

  struct sigaction action {};
  action.sa_handler = OnStopSignal;
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
  std::thread waiting([&feed, &o] {
    for (int i = 0; i < 50 && !g_stop; ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    if (!g_stop && feed.messages() == 0) {
      std::cerr << "hapticsim view: no message from hapticsimd on " << o.lcm_url
                << " after 5 s: is it running, with [lcm] enabled, on this URL?\n";
    }
  });
  server.Run(feed, g_stop);
  waiting.join();
  std::cout << "hapticsim view: stopped after " << feed.messages() << " messages ("
            << feed.decode_errors() << " undecodable)" << std::endl;
  return kExitOk;
}

}  // namespace

Command AddViewCommand(CLI::App& parent) {
  auto options = std::make_shared<ViewOptions>();
  CLI::App* app = parent.add_subcommand(
      "view",
      "Live view of a running hapticsimd in the browser: the object deforming, the tool tip, the "
      "force vector, the regions and the looked-up error against the target. Serves a page on "
      "127.0.0.1 only, fed from the daemon's LCM messages over a WebSocket; everything the page "
      "loads is inside this binary.");
  app->add_option("--port", options->server.port, "TCP port on 127.0.0.1 (0: any free one)")
      ->capture_default_str();
  app->add_option("--lcm-url", options->lcm_url, "LCM URL of the daemon (its lcm.url)")
      ->capture_default_str();
  app->add_option("--open", options->open,
                  "Start the desktop's browser on the page: auto (when $DISPLAY or "
                  "$WAYLAND_DISPLAY is set), yes or no")
      ->capture_default_str();
  app->add_option("--frame-rate", options->server.frame_rate_hz,
                  "Most updates per second sent to a page, Hz")
      ->capture_default_str();
  app->add_option("--device-channel", options->channels.device)->capture_default_str();
  app->add_option("--force-channel", options->channels.force)->capture_default_str();
  app->add_option("--status-channel", options->channels.status)->capture_default_str();
  app->add_option("--deformation-channel", options->channels.deformation,
                  "The daemon's lcm.deformation_channel")
      ->capture_default_str();
  return {app, [options] { return Run(*options); }};
}

}  // namespace hapticsim::cli
