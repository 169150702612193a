#include "ipc/service_socket.hpp"

#include <fcntl.h>
#include <grp.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <thread>

#include "core/error.hpp"
#include "ipc/file_mode.hpp"

namespace hapticsim::shm {
namespace {

std::string Why() { return std::strerror(errno); }

/** The greeting's first word: the protocol and its version. */
constexpr const char* kSessionGreeting = "HSIM1 session";
constexpr const char* kRefusedPrefix = "HSIM1 refused: ";

sockaddr_un AddressOf(const std::string& path, const std::string& key) {
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  HAPTICSIM_THROW_UNLESS(!path.empty() && path[0] == '/',
                         key + " = \"" + path + "\": must be an absolute path");
  HAPTICSIM_THROW_UNLESS(path.size() < sizeof address.sun_path,
                         key + " = \"" + path + "\": longer than a Unix socket path may be (" +
                             std::to_string(sizeof address.sun_path - 1) + " bytes)");
  std::memcpy(address.sun_path, path.c_str(), path.size() + 1);
  return address;
}

std::string DirectoryOf(const std::string& path) {
  const auto slash = path.rfind('/');
  return slash == 0 ? "/" : path.substr(0, slash);
}

/** Whether a live process answers at `address` (a socket a dead daemon left does not). */
bool SomeoneListens(const sockaddr_un& address) {
  UniqueFd probe(socket(AF_UNIX, SOCK_SEQPACKET | SOCK_NONBLOCK | SOCK_CLOEXEC, 0));
  if (!probe) return false;
  // Non-blocking: a full backlog (EAGAIN) is a live listener too, and never a wait.
  return connect(probe.get(), reinterpret_cast<const sockaddr*>(&address), sizeof address) == 0 ||
         errno == EAGAIN;
}

// Connects without ever blocking longer than `timeout_ms`: a Unix socket whose listen backlog is
// full (a flood, a stopped daemon) makes a blocking connect wait for good.
bool ConnectWithin(int socket, const sockaddr_un& address, int timeout_ms) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
  while (true) {
    if (connect(socket, reinterpret_cast<const sockaddr*>(&address), sizeof address) == 0) {
      return true;
    }
    if (errno != EAGAIN || std::chrono::steady_clock::now() >= deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

}  // namespace

PeerIdentity PeerOf(int fd) {
  PeerIdentity peer;
  ucred credentials{};
  socklen_t length = sizeof credentials;
  HAPTICSIM_THROW_UNLESS(getsockopt(fd, SOL_SOCKET, SO_PEERCRED, &credentials, &length) == 0,
                         "cannot read the peer's credentials: " + Why());
  peer.pid = credentials.pid;
  peer.uid = credentials.uid;
  peer.gid = credentials.gid;
  std::vector<gid_t> groups(64);
  for (int attempt = 0; attempt < 4; ++attempt) {
    socklen_t bytes = static_cast<socklen_t>(groups.size() * sizeof(gid_t));
    if (getsockopt(fd, SOL_SOCKET, SO_PEERGROUPS, groups.data(), &bytes) == 0) {
      groups.resize(bytes / sizeof(gid_t));
      peer.groups = std::move(groups);
      return peer;
    }
    if (errno != ERANGE) break;
    groups.resize(std::max<std::size_t>(bytes / sizeof(gid_t), groups.size() * 2));
  }
  return peer;  // no supplementary groups known: only the primary group counts
}

std::string PeerRefusal(const PeerIdentity& peer, uid_t daemon_uid, gid_t allowed_gid,
                        const std::string& group_name) {
  if (peer.uid == 0 || peer.uid == daemon_uid || peer.gid == allowed_gid) return "";
  if (std::find(peer.groups.begin(), peer.groups.end(), allowed_gid) != peer.groups.end()) {
    return "";
  }
  return "pid " + std::to_string(peer.pid) + " (uid " + std::to_string(peer.uid) +
         ") is not in group " + group_name + ": add that user to the group";
}

std::string ServerIdentityProblem(const std::string& path, const PeerIdentity& server,
                                  uid_t client_uid) {
  struct stat info {};
  if (lstat(path.c_str(), &info) != 0) return path + " cannot be examined: " + Why();
  if (!S_ISSOCK(info.st_mode)) return path + " is not a socket";
  if (info.st_uid != server.uid) {
    return path + " is owned by uid " + std::to_string(info.st_uid) + " but served by uid " +
           std::to_string(server.uid) + " (pid " + std::to_string(server.pid) +
           "): not the service that made it";
  }
  const std::string uids = "root, the service (uid " + std::to_string(server.uid) +
                           ") or this user (uid " + std::to_string(client_uid) + ")";
  // From the socket's own directory up to /, each examined itself (lstat: no symbolic link
  // can be re-pointed between the connection and this check).
  std::string directory = DirectoryOf(path);
  uid_t below_owner = 0;  // the owner of the directory one level down the path
  for (bool own_directory = true;; own_directory = false) {
    if (lstat(directory.c_str(), &info) != 0) return directory + " cannot be examined: " + Why();
    if (S_ISLNK(info.st_mode)) {
      return directory + " is a symbolic link: give the socket's real path";
    }
    if (info.st_uid != 0 && info.st_uid != server.uid && info.st_uid != client_uid) {
      return directory + " is owned by uid " + std::to_string(info.st_uid) + ", not " + uids +
             ": that user could have put " + path + " there";
    }
    if (info.st_mode & (S_IWGRP | S_IWOTH)) {
      // Others may create names here. In the socket's own directory that is enough to squat
      // the socket. Above it, a sticky directory (like /tmp) keeps them from moving what is
      // not theirs, so the directory below is safe if root or this user made it; not if anyone
      // else did, the service's user included (a squatter serves its own socket).
      const bool made_by_trusted = below_owner == 0 || below_owner == client_uid;
      if (own_directory || !(info.st_mode & S_ISVTX) || !made_by_trusted) {
        return directory + " (mode " + OctalMode(info.st_mode) +
               ") can be written by users other than its owner" +
               (own_directory || !(info.st_mode & S_ISVTX)
                    ? ""
                    : ", and the directory below it was made by uid " +
                          std::to_string(below_owner)) +
               ": any of them could have put " + path +
               " there; serve the socket from a directory only the service writes, e.g. "
               "/run/hapticsim";
      }
    }
    if (directory == "/") return "";
    below_owner = info.st_uid;
    directory = DirectoryOf(directory);
  }
}

ServiceListener::ServiceListener(const std::string& path, const std::string& group,
                                 const std::string& section)
    : path_(path), allowed_gid_(getegid()) {
  const std::string key = section + ".socket";
  const sockaddr_un address = AddressOf(path, key);
  if (!group.empty()) {
    const struct group* entry = getgrnam(group.c_str());
    HAPTICSIM_THROW_UNLESS(entry, section + ".group = \"" + group + "\": no such group");
    allowed_gid_ = entry->gr_gid;
  }
  // Named once here: getgrgid is neither thread-safe nor sure to be quick (a directory service).
  const struct group* named = getgrgid(allowed_gid_);
  group_name_ = named ? std::string(named->gr_name) : std::to_string(allowed_gid_);
  const std::string directory = DirectoryOf(path);
  struct stat info {};
  HAPTICSIM_THROW_UNLESS(stat(directory.c_str(), &info) == 0 && S_ISDIR(info.st_mode),
                         key + " = \"" + path + "\": " + directory +
                             " is not a directory: create it, only writable by the daemon's "
                             "user (systemd: RuntimeDirectory=hapticsim), or choose another path");
  // Anyone else who may write there could swap the socket between bind and chmod, or take the
  // name while the daemon is down; and drivers would refuse it (ServerIdentityProblem).
  HAPTICSIM_THROW_UNLESS(!(info.st_mode & (S_IWGRP | S_IWOTH)),
                         key + " = \"" + path + "\": " + directory + " (mode " +
                             OctalMode(info.st_mode) +
                             ") can be written by other users: use a directory only the daemon's "
                             "user can write (systemd: RuntimeDirectory=hapticsim), e.g. "
                             "mkdir -m 700");
  if (lstat(path.c_str(), &info) == 0) {
    HAPTICSIM_THROW_UNLESS(S_ISSOCK(info.st_mode), key + " = \"" + path +
                                                       "\": a file that is not a socket is in "
                                                       "the way; remove it or choose another path");
    HAPTICSIM_THROW_UNLESS(!SomeoneListens(address),
                           key + " = \"" + path +
                               "\": another hapticsimd already serves it; stop that one or "
                               "choose another path");
    unlink(path.c_str());  // left by a daemon that died
  }
  socket_.reset(socket(AF_UNIX, SOCK_SEQPACKET | SOCK_NONBLOCK | SOCK_CLOEXEC, 0));
  HAPTICSIM_THROW_UNLESS(socket_, "cannot make the service socket: " + Why());
  HAPTICSIM_THROW_UNLESS(
      bind(socket_.get(), reinterpret_cast<const sockaddr*>(&address), sizeof address) == 0,
      key + " = \"" + path + "\": cannot bind: " + Why());
  // Owner and group only, before anyone can connect (listen comes last).
  auto fail = [&](const std::string& what) {
    const std::string why = Why();
    unlink(path.c_str());
    throw Error(key + " = \"" + path + "\": cannot " + what + ": " + why);
  };
  if (lstat(path.c_str(), &info) != 0) fail("examine it");
  inode_ = info.st_ino;
  if (!group.empty() && chown(path.c_str(), static_cast<uid_t>(-1), allowed_gid_) != 0) {
    fail("give it to group " + group);
  }
  if (chmod(path.c_str(), 0660) != 0) fail("set its mode");
  if (listen(socket_.get(), 8) != 0) fail("listen");
}

ServiceListener::~ServiceListener() {
  struct stat info {};
  // Only the socket this listener bound: a newer daemon's at the same path stays.
  if (lstat(path_.c_str(), &info) == 0 && info.st_ino == inode_) unlink(path_.c_str());
}

std::optional<Connection> ServiceListener::Accept() {
  UniqueFd socket(accept4(socket_.get(), nullptr, nullptr, SOCK_NONBLOCK | SOCK_CLOEXEC));
  if (!socket) return std::nullopt;
  try {
    PeerIdentity peer = PeerOf(socket.get());
    return Connection{std::move(socket), std::move(peer)};
  } catch (const Error&) {
    return std::nullopt;  // gone before it could be asked: nobody to answer
  }
}

bool SendMessage(int socket, const std::string& text, int fd_to_pass) {
  iovec part{const_cast<char*>(text.data()), text.size()};
  msghdr message{};
  message.msg_iov = &part;
  message.msg_iovlen = 1;
  alignas(cmsghdr) char control[CMSG_SPACE(sizeof(int))] = {};
  if (fd_to_pass >= 0) {
    message.msg_control = control;
    message.msg_controllen = sizeof control;
    cmsghdr* header = CMSG_FIRSTHDR(&message);
    header->cmsg_level = SOL_SOCKET;
    header->cmsg_type = SCM_RIGHTS;
    header->cmsg_len = CMSG_LEN(sizeof(int));
    std::memcpy(CMSG_DATA(header), &fd_to_pass, sizeof(int));
  }
  return sendmsg(socket, &message, MSG_DONTWAIT | MSG_NOSIGNAL) ==
         static_cast<ssize_t>(text.size());
}

MappedSegment ReadSessionAnswer(int connection, const std::string& path, int timeout_ms) {
  pollfd ready{connection, POLLIN, 0};
  HAPTICSIM_THROW_UNLESS(
      poll(&ready, 1, timeout_ms) == 1,
      "hapticsimd at " + path + " did not answer within " + std::to_string(timeout_ms) + " ms");
  char text[256];
  iovec part{text, sizeof text - 1};
  alignas(cmsghdr) char control[CMSG_SPACE(4 * sizeof(int))] = {};
  msghdr message{};
  message.msg_iov = &part;
  message.msg_iovlen = 1;
  message.msg_control = control;
  message.msg_controllen = sizeof control;
  const ssize_t length = recvmsg(connection, &message, MSG_DONTWAIT | MSG_CMSG_CLOEXEC);
  HAPTICSIM_THROW_UNLESS(length >= 0, "cannot read hapticsimd's answer at " + path + ": " + Why());
  // Every descriptor that came, owned at once, so none leaks whatever is wrong with the message.
  std::vector<UniqueFd> passed;
  for (cmsghdr* h = CMSG_FIRSTHDR(&message); h; h = CMSG_NXTHDR(&message, h)) {
    if (h->cmsg_level != SOL_SOCKET || h->cmsg_type != SCM_RIGHTS) continue;
    const std::size_t count = (h->cmsg_len - CMSG_LEN(0)) / sizeof(int);
    for (std::size_t k = 0; k < count; ++k) {
      int fd;
      std::memcpy(&fd, CMSG_DATA(h) + k * sizeof(int), sizeof fd);
      passed.emplace_back(fd);
    }
  }
  HAPTICSIM_THROW_UNLESS(length > 0, "hapticsimd at " + path + " hung up without an answer");
  const std::string answer(text, static_cast<std::size_t>(length));
  if (answer.rfind(kRefusedPrefix, 0) == 0) {
    // The reason is the server's text: printable characters only reach the driver's log.
    const std::string why = Printable(answer.substr(std::strlen(kRefusedPrefix)));
    throw Error("hapticsimd at " + path + " refused this driver: " + why);
  }
  HAPTICSIM_THROW_UNLESS(answer == kSessionGreeting && passed.size() == 1 &&
                             !(message.msg_flags & (MSG_TRUNC | MSG_CTRUNC)),
                         "the service at " + path + " answered what hapticsimd does not say (" +
                             std::to_string(passed.size()) + " descriptors): not hapticsimd?");
  return MappedSegment::Adopt(passed[0].release(), path);
}

UniqueFd ConnectToDaemon(const std::string& path, const std::string& hint, int timeout_ms,
                         PeerIdentity* daemon) {
  const sockaddr_un address = AddressOf(path, "the daemon's socket");
  UniqueFd connection(socket(AF_UNIX, SOCK_SEQPACKET | SOCK_NONBLOCK | SOCK_CLOEXEC, 0));
  HAPTICSIM_THROW_UNLESS(connection, "cannot make a socket: " + Why());
  HAPTICSIM_THROW_UNLESS(ConnectWithin(connection.get(), address, timeout_ms),
                         "cannot connect to hapticsimd at " + path + ": " +
                             (errno == EAGAIN ? std::string("it takes no connection (busy or "
                                                            "stalled) within the timeout")
                                              : Why()) +
                             " (" + hint + ")");
  *daemon = PeerOf(connection.get());
  const std::string problem = ServerIdentityProblem(path, *daemon, geteuid());
  HAPTICSIM_THROW_UNLESS(problem.empty(), "refusing the daemon at " + path + ": " + problem);
  return connection;
}

ServiceSession ConnectToService(const std::string& path, int timeout_ms) {
  PeerIdentity daemon;
  UniqueFd connection = ConnectToDaemon(path,
                                        "is it running with [shm] enabled = true and socket = \"" +
                                            path + "\", and is this user in its shm.group?",
                                        timeout_ms, &daemon);
  MappedSegment segment = ReadSessionAnswer(connection.get(), path, timeout_ms);
  return ServiceSession{std::move(connection), std::move(daemon), std::move(segment)};
}

std::string SessionGreeting() { return kSessionGreeting; }
std::string Refusal(const std::string& why) { return kRefusedPrefix + why; }

}  // namespace hapticsim::shm
