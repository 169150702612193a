#include "tools/view/view_server.hpp"

#include <fcntl.h>
#include <poll.h>
#include <sys/socket.h>

#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <chrono>
#include <system_error>

#include "core/error.hpp"
#include "tools/view/view_assets.hpp"

namespace hapticsim::view {
namespace {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;
using Request = http::request<http::string_body>;

// Browsers leave the port out of Host and Origin when it is 80.
std::string PortSuffix(int port) { return port == 80 ? "" : ":" + std::to_string(port); }

bool HostIsOurs(std::string_view host, int port) {
  const std::string p = PortSuffix(port);
  return host == "127.0.0.1" + p || host == "localhost" + p;
}

bool OriginIsOurs(std::string_view origin, int port) {
  const std::string p = PortSuffix(port);
  return origin == "http://127.0.0.1" + p || origin == "http://localhost" + p;
}

http::response<http::string_body> Respond(const Request& request, http::status status,
                                          std::string_view content_type, std::string body) {
  http::response<http::string_body> response{status, request.version()};
  response.set(http::field::server, "hapticsim view");
  response.set(http::field::content_type,
               beast::string_view(content_type.data(), content_type.size()));
  response.set(http::field::cache_control, "no-store");
  response.keep_alive(request.keep_alive());
  response.body() = std::move(body);
  response.prepare_payload();
  return response;
}

http::response<http::string_body> AssetOrError(const Request& request) {
  if (request.method() != http::verb::get && request.method() != http::verb::head) {
    return Respond(request, http::status::method_not_allowed, "text/plain", "GET only\n");
  }
  const std::string_view target(request.target().data(), request.target().size());
  const std::string_view path = target.substr(0, target.find('?'));
  for (const ViewAsset& asset : ViewAssets()) {
    if (asset.path == path || (asset.path == "/" && path == "/index.html")) {
      auto response =
          Respond(request, http::status::ok, asset.content_type, std::string(asset.body));
      if (request.method() == http::verb::head) response.body().clear();
      return response;
    }
  }
  return Respond(request, http::status::not_found, "text/plain",
                 "hapticsim view has no " + std::string(path) + "\n");
}

using Clock = std::chrono::steady_clock;

// While alive, the blocking read or write it guards must end within `limit`, or the server shuts
// the connection's socket down (ViewServer::Reap): asio's blocking calls wait out SO_RCVTIMEO,
// so a peer that stops reading or sending would otherwise hold its slot for good.
class Deadline {
 public:
  Deadline(std::atomic<int64_t>& deadline, std::chrono::seconds limit) : deadline_(deadline) {
    deadline_ = (Clock::now() + limit).time_since_epoch().count();
  }
  ~Deadline() { deadline_ = 0; }
  Deadline(const Deadline&) = delete;
  Deadline& operator=(const Deadline&) = delete;

 private:
  std::atomic<int64_t>& deadline_;
};

constexpr std::chrono::seconds kReadLimit{10}, kWriteLimit{5};

// The page went away (closed, reloaded): its FIN or reset, seen without reading. A page that
// goes while nothing is sent would otherwise keep its connection's slot.
bool PeerClosed(int fd) {
  pollfd p{fd, POLLRDHUP, 0};
  return ::poll(&p, 1, 0) > 0 && (p.revents & (POLLRDHUP | POLLHUP | POLLERR)) != 0;
}

// Sends the hello, then the newest of each kind of message whenever the feed has a newer one, at
// most frame_rate_hz times a second: a page that draws slower gets fewer, newer frames.
void StreamFeed(websocket::stream<tcp::socket&>& ws, const ViewFeed& feed,
                const ServerSettings& settings, const std::atomic<bool>& stopping,
                std::atomic<int64_t>& deadline) {
  const auto frame = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(1.0 / settings.frame_rate_hz));
  boost::system::error_code ec;
  ws.text(true);
  {
    Deadline limit(deadline, kWriteLimit);
    ws.write(asio::buffer(settings.hello_json), ec);
  }
  FeedSnapshot seen;
  auto next = Clock::now();
  while (!ec && !stopping && !PeerClosed(ws.next_layer().native_handle())) {
    const FeedSnapshot now = feed.WaitNewer(seen.version, std::chrono::milliseconds(200));
    const auto send = [&](const FeedSnapshot::Text& text, uint64_t version, uint64_t seen_version) {
      if (!ec && version > seen_version && text) {
        Deadline limit(deadline, kWriteLimit);
        ws.write(asio::buffer(*text), ec);
      }
    };
    send(now.status, now.status_version, seen.status_version);
    send(now.deformation, now.deformation_version, seen.deformation_version);
    send(now.force, now.force_version, seen.force_version);
    send(now.tool, now.tool_version, seen.tool_version);
    seen = now;
    next = std::max(next + frame, Clock::now());
    std::this_thread::sleep_until(next);
  }
  // No ws.close() at a stop: its teardown would close the socket, whose descriptor the server
  // shuts down from its own thread (ViewServer::Reap); the browser sees the connection end.
}

// Descriptors of the server and its connections are not handed to programs it starts (xdg-open,
// and the browser that may outlive it).
void CloseOnExec(int fd) { ::fcntl(fd, F_SETFD, ::fcntl(fd, F_GETFD) | FD_CLOEXEC); }

}  // namespace

struct ViewServer::Connection {
  explicit Connection(tcp::socket s) : socket(std::move(s)), fd(socket.native_handle()) {}
  tcp::socket socket;
  int fd;
  std::thread thread;
  std::atomic<bool> done{false};
  std::atomic<int64_t> deadline{0};  ///< Clock ticks a blocking call must end by; 0: none
};

class ViewServer::Impl {
 public:
  asio::io_context io;
  tcp::acceptor acceptor{io};
};

ViewServer::ViewServer(ServerSettings settings)
    : settings_(std::move(settings)), impl_(std::make_unique<Impl>()) {
  HAPTICSIM_THROW_UNLESS(settings_.port >= 0 && settings_.port <= 65535,
                         "--port " + std::to_string(settings_.port) + ": use 0 to 65535");
  HAPTICSIM_THROW_UNLESS(settings_.frame_rate_hz >= 1 && settings_.frame_rate_hz <= 1000,
                         "--frame-rate must be 1 to 1000 Hz");
  const tcp::endpoint endpoint(asio::ip::address_v4::loopback(),
                               static_cast<unsigned short>(settings_.port));
  boost::system::error_code ec;
  auto& acceptor = impl_->acceptor;
  acceptor.open(endpoint.protocol(), ec);
  if (!ec) CloseOnExec(acceptor.native_handle());
  if (!ec) acceptor.set_option(tcp::acceptor::reuse_address(true), ec);
  if (!ec) acceptor.bind(endpoint, ec);
  if (!ec) acceptor.listen(asio::socket_base::max_listen_connections, ec);
  HAPTICSIM_THROW_UNLESS(!ec, "cannot listen on 127.0.0.1:" + std::to_string(settings_.port) +
                                  ": " + ec.message() +
                                  (ec == asio::error::address_in_use
                                       ? " (another program, or another hapticsim view, has it: "
                                         "choose another with --port, or --port 0 for any)"
                                       : ""));
  port_ = acceptor.local_endpoint().port();
}

ViewServer::~ViewServer() {
  stopping_ = true;
  Reap(/*all=*/true);
}

void ViewServer::Run(const ViewFeed& feed, const std::atomic<bool>& stop) {
  feed_ = &feed;
  auto& acceptor = impl_->acceptor;
  while (!stop) {
    Reap(/*all=*/false);
    pollfd pfd{acceptor.native_handle(), POLLIN, 0};
    if (::poll(&pfd, 1, 200) <= 0) continue;
    boost::system::error_code ec;
    tcp::socket socket(impl_->io);
    acceptor.accept(socket, ec);
    if (ec) continue;
    CloseOnExec(socket.native_handle());
    std::lock_guard lock(connections_mutex_);
    if (connections_.size() >= kMaxConnections) continue;  // closed as it goes out of scope
    Connection& c = connections_.emplace_back(std::move(socket));
    try {
      c.thread = std::thread([this, &c] {
        Serve(c);
        c.done = true;
      });
    } catch (const std::system_error&) {
      connections_.pop_back();  // no thread to serve it: closed
    }
  }
  stopping_ = true;
  Reap(/*all=*/true);
}

// Joins the connections that ended; shuts down those past their deadline and, with all, every
// one, which ends any read or write a connection's thread is blocked in. A connection's
// descriptor stays open until its thread is joined, so the one shut down is never another's.
void ViewServer::Reap(bool all) {
  std::list<Connection> ended;
  {
    std::lock_guard lock(connections_mutex_);
    const int64_t now = Clock::now().time_since_epoch().count();
    for (auto it = connections_.begin(); it != connections_.end();) {
      const int64_t deadline = it->deadline;
      if (all || (deadline != 0 && now > deadline)) ::shutdown(it->fd, SHUT_RDWR);
      auto next = std::next(it);
      if (all || it->done) ended.splice(ended.end(), connections_, it);
      it = next;
    }
  }
  for (Connection& c : ended) c.thread.join();
}

void ViewServer::Serve(Connection& connection) {
  beast::flat_buffer buffer;
  boost::system::error_code ec;
  while (!stopping_) {
    http::request_parser<http::string_body> parser;
    parser.header_limit(8 * 1024);
    parser.body_limit(4 * 1024);
    {
      Deadline limit(connection.deadline, kReadLimit);
      http::read(connection.socket, buffer, parser, ec);
    }
    if (ec) return;
    Request request = parser.release();
    const auto host = request[http::field::host];
    if (!HostIsOurs(std::string_view(host.data(), host.size()), port_)) {
      http::write(
          connection.socket,
          Respond(request, http::status::forbidden, "text/plain",
                  "hapticsim view answers only http://127.0.0.1:" + std::to_string(port_) + "/\n"),
          ec);
      return;
    }
    if (websocket::is_upgrade(request) && request.target() == "/feed") {
      const auto origin = request[http::field::origin];
      if (!OriginIsOurs(std::string_view(origin.data(), origin.size()), port_)) {
        http::write(connection.socket,
                    Respond(request, http::status::forbidden, "text/plain",
                            "the feed is for hapticsim view's own page\n"),
                    ec);
        return;
      }
      websocket::stream<tcp::socket&> ws(connection.socket);
      ws.accept(request, ec);
      if (ec) return;
      StreamFeed(ws, *feed_, settings_, stopping_, connection.deadline);
      return;
    }
    {
      Deadline limit(connection.deadline, kWriteLimit);
      http::write(connection.socket, AssetOrError(request), ec);
    }
    if (ec || !request.keep_alive()) return;
  }
}

}  // namespace hapticsim::view
