#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "ipc/service_socket.hpp"

namespace hapticsim {

/** One request from `hapticsim ctl`, from a user the daemon admitted, waiting for its answer. */
struct ControlRequest {
  shm::UniqueFd connection;
  shm::PeerIdentity peer;
  std::string line;  ///< the request (daemon/control_line.hpp)
};

/**
 * The control socket (control.socket, mode 0660, group control.group): where state-changing
 * commands come from. The daemon asks the kernel who connected (as for shared memory): root, its
 * own user and the group's members are admitted, anyone else is answered "refused: …" and
 * counted. An admitted client sends one request line and gets one answer. Never blocks: a client
 * that does not send its request within kRequestTimeout_ns is refused, and at most kMaxPending
 * wait at once. Only the supervisor's thread uses it.
 */
class ControlServer {
 public:
  static constexpr std::int64_t kRequestTimeout_ns = 1'000'000'000;
  static constexpr std::size_t kMaxPending = 8;
  static constexpr std::size_t kMaxRequestBytes = 256;

  /** @throws Error naming control.socket or control.group and what to fix. */
  ControlServer(const std::string& path, const std::string& group);

  /** The next complete request, if one came; refusals are answered here. */
  std::optional<ControlRequest> Next(std::int64_t now_ns);
  /** Answers `request` ("ok: …" or "refused: …") and hangs up. */
  static void Answer(ControlRequest& request, const std::string& text);

  /** Connections refused: credentials, too many at once, no request in time, too long. */
  std::int64_t refused() const { return refused_; }
  /** The newest refusal's reason (for the log), empty when none yet. */
  const std::string& last_refusal() const { return last_refusal_; }
  const std::string& path() const { return listener_.path(); }

 private:
  struct Pending {
    shm::Connection connection;
    std::int64_t deadline_ns;
    std::string refusal;  ///< why the peer is not admitted: answered once its request is read
  };
  void Refuse(int connection, const std::string& why);

  shm::ServiceListener listener_;
  std::vector<Pending> pending_;
  std::int64_t refused_ = 0;
  std::string last_refusal_;
};

}  // namespace hapticsim
