#include "ipc/control_client.hpp"

#include <poll.h>
#include <sys/socket.h>

#include "core/error.hpp"
#include "ipc/service_socket.hpp"

namespace hapticsim::shm {

std::string SendControlRequest(const std::string& path, const std::string& line, int timeout_ms) {
  PeerIdentity daemon;
  UniqueFd connection =
      ConnectToDaemon(path,
                      "is hapticsimd running with [control] socket = \"" + path +
                          "\", and is this user root, the daemon's or in its control.group?",
                      timeout_ms, &daemon);
  // The daemon may hang up with its answer before reading a request it will not take (too many
  // at once): then sending fails, and that answer is still read.
  const bool sent = SendMessage(connection.get(), line);
  pollfd ready{connection.get(), POLLIN, 0};
  HAPTICSIM_THROW_UNLESS(
      poll(&ready, 1, timeout_ms) == 1,
      "hapticsimd at " + path + " did not answer within " + std::to_string(timeout_ms) + " ms");
  char text[512];
  const ssize_t n = recv(connection.get(), text, sizeof text, MSG_DONTWAIT);
  HAPTICSIM_THROW_UNLESS(
      n > 0, "hapticsimd at " + path + (sent ? " hung up without an answer" : " took no request"));
  return Printable(std::string(text, static_cast<std::size_t>(n)));  // shown on a terminal
}

}  // namespace hapticsim::shm
