#include "daemon/control_server.hpp"

#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>

namespace hapticsim {
namespace {

/** Connections taken per call: a flood waits in the listen backlog, not in the supervisor. */
constexpr int kAcceptsPerCall = 4;

}  // namespace

ControlServer::ControlServer(const std::string& path, const std::string& group)
    : listener_(path, group, "control") {}

void ControlServer::Refuse(int connection, const std::string& why) {
  ++refused_;
  last_refusal_ = why;
  shm::SendMessage(connection, "refused: " + why);
}

std::optional<ControlRequest> ControlServer::Next(std::int64_t now_ns) {
  for (int k = 0; k < kAcceptsPerCall; ++k) {
    std::optional<shm::Connection> connection = listener_.Accept();
    if (!connection) break;
    if (pending_.size() >= kMaxPending) {
      Refuse(connection->socket.get(), "too many requests at once; try again");
      continue;
    }
    // Even a peer that is not admitted is answered only after its request is read: a Unix
    // socket closed with an unread request makes the client's receive fail (ECONNRESET), and
    // the refusal would be lost.
    std::string refusal = listener_.Refusal(connection->peer);
    pending_.push_back({std::move(*connection), now_ns + kRequestTimeout_ns, std::move(refusal)});
  }
  for (std::size_t i = 0; i < pending_.size();) {
    Pending& p = pending_[i];
    char text[kMaxRequestBytes + 1];
    const ssize_t n = recv(p.connection.socket.get(), text, sizeof text, MSG_DONTWAIT);
    const bool waiting = n < 0 && (errno == EAGAIN || errno == EINTR);
    if (waiting && now_ns < p.deadline_ns) {
      ++i;
      continue;
    }
    Pending taken = std::move(p);
    pending_.erase(pending_.begin() + static_cast<std::ptrdiff_t>(i));
    if (!taken.refusal.empty()) {
      if (n >= 0 || waiting) Refuse(taken.connection.socket.get(), taken.refusal);
    } else if (waiting) {
      Refuse(taken.connection.socket.get(), "no request within 1 s");
    } else if (n > static_cast<ssize_t>(kMaxRequestBytes)) {
      Refuse(taken.connection.socket.get(), "a request longer than 256 bytes");
    } else if (n > 0) {
      return ControlRequest{std::move(taken.connection.socket), taken.connection.peer,
                            std::string(text, static_cast<std::size_t>(n))};
    }
    // n == 0 or an error: the client left without asking; nothing to answer.
  }
  return std::nullopt;
}

void ControlServer::Answer(ControlRequest& request, const std::string& text) {
  shm::SendMessage(request.connection.get(), text);
  request.connection.reset();
}

}  // namespace hapticsim
