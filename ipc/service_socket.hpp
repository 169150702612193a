#pragma once

// The service socket: how a device driver gets its shared segment from hapticsimd, and how each
// side makes sure of the other.
//
// The daemon listens on a Unix socket (shm.socket, default /run/hapticsim/hapticsimd.sock; mode
// 0660, group shm.group). A driver connects; the daemon reads the driver's credentials from the
// kernel (SO_PEERCRED, SO_PEERGROUPS) and either answers "HSIM1 session" with a new sealed segment
// attached (SCM_RIGHTS; ipc/shm_segment.hpp), or "HSIM1 refused: <why>" and hangs up. The session
// lasts while the driver keeps the connection open; one driver at a time. The driver checks the
// daemon too (ServerIdentityProblem): the socket must be owned by the process that serves it, in
// a directory nobody else can write, so no other local user can have put it there first.

#include <sys/types.h>
#include <unistd.h>

#include <optional>
#include <string>
#include <vector>

#include "ipc/shm_segment.hpp"
#include "ipc/unique_fd.hpp"

namespace hapticsim::shm {

/** Where hapticsimd listens unless shm.socket says otherwise (systemd: RuntimeDirectory). */
inline constexpr const char* kDefaultSocket = "/run/hapticsim/hapticsimd.sock";

/** The process at the other end of a connected Unix socket, as the kernel tells it. */
struct PeerIdentity {
  pid_t pid = 0;
  uid_t uid = 0;
  gid_t gid = 0;
  std::vector<gid_t> groups;  ///< supplementary groups (SO_PEERGROUPS)
};

/** The identity of the peer of connected Unix socket `fd`. @throws Error when unreadable. */
PeerIdentity PeerOf(int fd);

/**
 * Whether `peer` may drive the daemon running as `daemon_uid`: root, the daemon's own user, or a
 * member of `allowed_gid` (as its primary or a supplementary group). Empty when it may, else why
 * not, in words for the log.
 */
std::string PeerRefusal(const PeerIdentity& peer, uid_t daemon_uid, gid_t allowed_gid,
                        const std::string& group_name);

/**
 * Why the socket at `path`, served by `server`, is not to be trusted by a client running as
 * `client_uid`; empty when it is. The socket must be owned by the serving user. Every directory
 * from the socket's up to / must be a real directory (no symbolic link), owned by root, the
 * serving user or the client's, and writable by no one else — except that a sticky directory
 * above the socket's own (like /tmp) may be, when the directory below it on the path was made by
 * root or the client: so no other user can have put the socket there first.
 */
std::string ServerIdentityProblem(const std::string& path, const PeerIdentity& server,
                                  uid_t client_uid);

/** A connection the daemon accepted: the socket and who is at the other end. */
struct Connection {
  UniqueFd socket;
  PeerIdentity peer;
};

/** The daemon's side: listens at `path` for drivers. Only the daemon's I/O thread uses it. */
class ServiceListener {
 public:
  /**
   * Binds `path` (mode 0660, group `group`, or the daemon's own group when empty). A socket left
   * there by a daemon that died is replaced; a live daemon's, or any other file, is not.
   * `section` is the config section that named them ("shm", "control"), for messages.
   * @throws Error naming the key and what to fix.
   */
  ServiceListener(const std::string& path, const std::string& group,
                  const std::string& section = "shm");
  ~ServiceListener();
  ServiceListener(const ServiceListener&) = delete;
  ServiceListener& operator=(const ServiceListener&) = delete;

  /** A connection waiting to be accepted, or nothing (never blocks). */
  std::optional<Connection> Accept();
  const std::string& path() const { return path_; }
  gid_t allowed_gid() const { return allowed_gid_; }
  const std::string& group_name() const { return group_name_; }
  /** Why `peer` may not connect here (PeerRefusal); empty when it may. */
  std::string Refusal(const PeerIdentity& peer) const {
    return PeerRefusal(peer, geteuid(), allowed_gid_, group_name_);
  }

 private:
  std::string path_;
  UniqueFd socket_;
  gid_t allowed_gid_;
  std::string group_name_;
  ino_t inode_ = 0;  // of the socket file bound, so only that one is removed at the end
};

/**
 * Sends `text` as one message, with `fd_to_pass` attached when it is >= 0. Never blocks; false
 * when the message could not be sent whole.
 */
bool SendMessage(int socket, const std::string& text, int fd_to_pass = -1);

/**
 * `text` as it may be shown on a terminal or in a log when someone else wrote it: every byte
 * outside printable ASCII becomes '?' (no terminal escapes).
 */
inline std::string Printable(std::string text) {
  for (char& c : text) {
    if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7f) c = '?';
  }
  return text;
}

/** The daemon's answers: a session (sent with the segment attached), or a refusal and why. */
std::string SessionGreeting();
std::string Refusal(const std::string& why);

/** A driver's session with the daemon: held open for as long as the driver drives. */
struct ServiceSession {
  UniqueFd connection;
  PeerIdentity daemon;
  MappedSegment segment;
};

/**
 * A client's side: connects to the daemon's socket at `path` within `timeout_ms` and checks that
 * the daemon is the service (ServerIdentityProblem), filling `daemon`. `hint` says what to check
 * when nothing answers there. The connection is non-blocking. @throws Error naming the problem.
 */
UniqueFd ConnectToDaemon(const std::string& path, const std::string& hint, int timeout_ms,
                         PeerIdentity* daemon);

/**
 * The driver's side of the answer: waits at most `timeout_ms` for the daemon's message on
 * `connection` and maps the segment it carries; every descriptor that came with it is closed
 * otherwise. `path` names the daemon in messages. @throws Error: a refusal (with the daemon's
 * reason), a hang-up, silence, or an answer or segment that is not hapticsimd's.
 */
MappedSegment ReadSessionAnswer(int connection, const std::string& path, int timeout_ms);

/**
 * The driver's side: connects to the daemon at `path`, checks that it is the service
 * (ServerIdentityProblem), and maps the segment it hands over, waiting at most `timeout_ms` for
 * it. @throws Error that names the problem: no daemon, an untrusted socket, refused, no segment.
 */
ServiceSession ConnectToService(const std::string& path, int timeout_ms);

}  // namespace hapticsim::shm
