#pragma once
// hapticsim view's web server: the page's files and a WebSocket that streams the feed's newest
// messages, on 127.0.0.1 only. A thread per connection (a page needs two or three), at most
// kMaxConnections at once; requests whose Host or Origin is not this server's own are refused, so
// a web site open in the same browser cannot read the feed through DNS rebinding.
#include <atomic>
#include <list>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "tools/view/view_feed.hpp"

namespace hapticsim::view {

struct ServerSettings {
  int port = 8765;            ///< TCP port on 127.0.0.1; 0: any free port (see port())
  double frame_rate_hz = 60;  ///< most WebSocket updates per second to one page
  std::string hello_json;     ///< sent first on every WebSocket: what the page is connected to
};

class ViewServer {
 public:
  static constexpr int kMaxConnections = 32;

  /** Binds 127.0.0.1:port; throws hapticsim::Error naming the port when it cannot. */
  explicit ViewServer(ServerSettings settings);
  ~ViewServer();
  ViewServer(const ViewServer&) = delete;
  ViewServer& operator=(const ViewServer&) = delete;

  int port() const { return port_; }

  /** Serves the page and `feed` until `stop` is set (checked every 200 ms), then closes every
   *  connection. */
  void Run(const ViewFeed& feed, const std::atomic<bool>& stop);

 private:
  struct Connection;
  class Impl;
  void Serve(Connection& connection);
  void Reap(bool all);

  const ViewFeed* feed_ = nullptr;
  ServerSettings settings_;
  std::unique_ptr<Impl> impl_;
  int port_ = 0;
  std::atomic<bool> stopping_{false};
  std::mutex connections_mutex_;
  std::list<Connection> connections_;
};

}  // namespace hapticsim::view
