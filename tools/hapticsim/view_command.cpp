// hapticsim view: a live picture of a running hapticsimd in the browser. It listens to the
// daemon's LCM messages (device input, force, status, deformed surface) and serves a page on
// 127.0.0.1 that draws them with three.js; see docs/simulator.md, "A live view".
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>
#include <thread>

#include "core/error.hpp"
#include "core/scene/object_surface.hpp"
#include "core/scene/scene_model.hpp"
#include "core/scene/scene_toml.hpp"
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
  std::string scene_file;  // --scene: the daemon's scene, for its object's surface
};

#if HAPTICSIM_WITH_VIEW
std::atomic<bool> g_stop{false};
void OnStopSignal(int) { g_stop = true; }

// Starts the desktop's browser on the page (xdg-open), without waiting for it: in a session of
// its own (Ctrl-C here does not close the browser) and with none of our descriptors (a browser
// it starts must not keep LCM's sockets or the server's port).
void OpenBrowser(const std::string& url) {
  const char* argv[] = {"xdg-open", url.c_str(), nullptr};
  posix_spawnattr_t attributes;
  posix_spawn_file_actions_t actions;
  posix_spawnattr_init(&attributes);
  posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETSID);
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addclosefrom_np(&actions, 3);
  pid_t pid = 0;
  const int failed =
      posix_spawnp(&pid, "xdg-open", &actions, &attributes, const_cast<char**>(argv), environ);
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attributes);
  if (failed != 0) {
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
  nlohmann::json hello{{"type", "hello"},
                       {"lcm_url", o.lcm_url},
                       {"channels",
                        {{"device", channels.device},
                         {"force", channels.force},
                         {"status", channels.status},
                         {"deformation", channels.deformation}}}};
  if (!o.scene_file.empty()) {
    // The object's faces, for an object whose surface ids alone do not say which squares are its
    // faces (one that leaves voxels empty): drawn instead of the box's.
    const SceneObject object = DescribeSceneObject(LoadSceneFile(o.scene_file));
    hello["surface_quads"] = ObjectSurfaceQuads(object);
    hello["nodes_per_axis"] = std::max({object.grid.nx(), object.grid.ny(), object.grid.nz()});
    hello["scene"] = o.scene_file;
  }
  settings.hello_json = hello.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  struct sigaction action {};
  action.sa_handler = OnStopSignal;
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
  // The port first: a command line it refuses never starts LCM. The feed outlives the server's
  // connection threads, which read it, whatever way Run ends.
  std::optional<view::ViewFeed> feed;
  view::ViewServer server(settings);
  const std::string url = "http://127.0.0.1:" + std::to_string(server.port()) + "/";
  feed.emplace(o.lcm_url, channels);
  const bool desktop = std::getenv("DISPLAY") || std::getenv("WAYLAND_DISPLAY");
  if (o.open == "yes" || (o.open == "auto" && desktop)) OpenBrowser(url);
  std::cout << "hapticsim view: serving " << url << " (listening to " << o.lcm_url
            << "); Ctrl-C stops" << std::endl;
  std::jthread waiting([&feed = *feed, &o] {
    for (int i = 0; i < 50 && !g_stop; ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    if (!g_stop && feed.messages() == 0) {
      std::cerr << "hapticsim view: no message from hapticsimd on " << o.lcm_url
                << " after 5 s: is it running, with [lcm] enabled, on this URL?\n";
    }
  });
  server.Run(*feed, g_stop);
  waiting.join();
  std::cout << "hapticsim view: stopped after " << feed->messages() << " messages ("
            << feed->decode_errors() << " undecodable)" << std::endl;
  return kExitOk;
}
#else
int Run(const ViewOptions&) {
  throw Error(
      "this hapticsim was built without the live view: web/view/node_modules was missing when it "
      "was configured; run scripts/setup.sh (npm ci in web/view fetches three.js), then build "
      "again");
}
#endif

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
  app->add_option("--scene", options->scene_file,
                  "The daemon's scene file ([scene] file in its config): draws its object's own "
                  "faces, which an object that leaves voxels of its lattice empty needs (without "
                  "it the page draws the faces of the lattice's box)");
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
