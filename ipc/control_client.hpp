#pragma once

#include <string>

namespace hapticsim::shm {

/** Where hapticsimd takes hapticsim ctl's requests unless control.socket says otherwise. */
inline constexpr const char* kDefaultControlSocket = "/run/hapticsim/control.sock";

/**
 * Sends one request line (daemon/control_line.hpp) to the daemon's control socket at `path`,
 * after checking that the daemon is the service (ServerIdentityProblem), and returns its answer:
 * "ok: …" or "refused: …". @throws Error when nothing answers there, the socket is not to be
 * trusted, or no answer comes within `timeout_ms`.
 */
std::string SendControlRequest(const std::string& path, const std::string& line, int timeout_ms);

}  // namespace hapticsim::shm
