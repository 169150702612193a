// The service socket and the sealed segment (ipc/service_socket.hpp, ipc/shm_segment.hpp), with
// real Unix sockets, real memory files and real file modes: what a driver accepts from a server,
// and what it refuses, by name.
#include "ipc/service_socket.hpp"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/mman.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include "core/error.hpp"
#include "ipc/shm_device_client.hpp"
#include "tests/support/private_socket.hpp"

namespace hapticsim::shm {
namespace {

std::string DirectoryOf(const std::string& path) {
  return std::filesystem::path(path).parent_path().string();
}

// A server at `path` that answers the first driver to connect with `answer(connection)`. Raw
// socket calls, as a squatter would make them (ServiceListener refuses directories others can
// write).
class FakeServer {
 public:
  FakeServer(const std::string& path, std::function<void(int)> answer)
      : listener_(socket(AF_UNIX, SOCK_SEQPACKET | SOCK_NONBLOCK | SOCK_CLOEXEC, 0)) {
    sockaddr_un address{};
    address.sun_family = AF_UNIX;
    std::snprintf(address.sun_path, sizeof address.sun_path, "%s", path.c_str());
    unlink(path.c_str());
    EXPECT_EQ(bind(listener_.get(), reinterpret_cast<sockaddr*>(&address), sizeof address), 0);
    EXPECT_EQ(listen(listener_.get(), 8), 0);
    thread_ = std::thread([this, answer] {
      for (int n = 0; n < 2000; ++n) {
        UniqueFd connection(accept4(listener_.get(), nullptr, nullptr, SOCK_CLOEXEC));
        if (connection) {
          answer(connection.get());
          // Held open until the driver has read the answer.
          std::this_thread::sleep_for(std::chrono::milliseconds(100));
          return;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
      }
    });
  }
  ~FakeServer() { thread_.join(); }

 private:
  UniqueFd listener_;
  std::thread thread_;
};

// What ConnectToService says about the server at `path`; empty when it connects.
std::string DriverVerdict(const std::string& path) {
  try {
    ConnectToService(path, 1000);
    return "";
  } catch (const Error& e) {
    return e.what();
  }
}

// Why a daemon could not listen at `path`; empty when it could.
std::string ListenerRefusal(const std::string& path) {
  try {
    ServiceListener listener(path, "");
    return "";
  } catch (const Error& e) {
    return e.what();
  }
}

int MemoryFile(std::size_t bytes, bool sealed) {
  const int fd = memfd_create("foreign", MFD_CLOEXEC | MFD_ALLOW_SEALING);
  EXPECT_EQ(ftruncate(fd, static_cast<off_t>(bytes)), 0);
  if (sealed) EXPECT_EQ(fcntl(fd, F_ADD_SEALS, F_SEAL_SHRINK | F_SEAL_GROW | F_SEAL_SEAL), 0);
  return fd;
}

TEST(SealedSegment, NeitherItsMakerNorItsDriverCanChangeItsSizeOrItsSeals) {
  MappedSegment daemon = MappedSegment::CreateSealed("hapticsim-test");
  const int driver = dup(daemon.fd());
  EXPECT_NE(ftruncate(driver, 0), 0);  // a SIGBUS in the daemon's next access, before
  EXPECT_EQ(errno, EPERM);
  EXPECT_NE(ftruncate(driver, 2 * sizeof(ShmSegment)), 0);
  EXPECT_EQ(errno, EPERM);
  EXPECT_NE(fallocate(driver, 0, 0, 4 * sizeof(ShmSegment)), 0);
  EXPECT_NE(fcntl(driver, F_ADD_SEALS, F_SEAL_WRITE), 0);  // sealed: no more seals either
  struct stat info {};
  ASSERT_EQ(fstat(driver, &info), 0);
  EXPECT_EQ(static_cast<std::size_t>(info.st_size), SegmentBytes(0));
  // The driver's mapping is the daemon's memory.
  MappedSegment mapped = MappedSegment::Adopt(driver, "the test");
  daemon.segment().newest_output.store(42);
  EXPECT_EQ(mapped.segment().newest_output.load(), 42);
}

TEST(SealedSegment, ADriverRefusesAnUnsealedFileAWrongSizeAndAForeignHeader) {
  auto verdict = [](int fd) {
    try {
      MappedSegment::Adopt(fd, "the server");
      return std::string();
    } catch (const Error& e) {
      return std::string(e.what());
    }
  };
  EXPECT_NE(verdict(MemoryFile(sizeof(ShmSegment), false)).find("not sealed against size changes"),
            std::string::npos);
  EXPECT_NE(verdict(MemoryFile(4096, true)).find("has 4096 bytes; this client expects"),
            std::string::npos);
  // The right size, sealed, but all zeros: nobody's header.
  EXPECT_NE(verdict(MemoryFile(sizeof(ShmSegment), true)).find("no hapticsim signature"),
            std::string::npos);
  // A regular file cannot be sealed at all.
  char path[] = "/tmp/hapticsim-regular-XXXXXX";
  const int regular = mkstemp(path);
  unlink(path);
  ASSERT_EQ(ftruncate(regular, sizeof(ShmSegment)), 0);
  EXPECT_NE(verdict(regular).find("not a sealable memory file"), std::string::npos);
}

// The deformed surface's area: a frame written by the daemon reads back whole in the driver's
// mapping, and its size is what each side saw when the segment was made or adopted, whatever
// the other side writes into the header afterwards (a driver could otherwise make the daemon
// write past its mapping).
TEST(SealedSegment, TheDeformationAreaReadsBackAndKeepsTheSizeItWasMadeWith) {
  MappedSegment daemon = MappedSegment::CreateSealed("hapticsim-test", 10);
  MappedSegment driver = MappedSegment::Adopt(dup(daemon.fd()), "the test");
  ASSERT_EQ(driver.deformation().nodes(), 10u);
  ShmDeformationFrame meta;
  EXPECT_FALSE(driver.deformation().Read(&meta, nullptr, nullptr)) << "nothing written yet";
  driver.segment().header.deformation_nodes = 100'000;  // a hostile driver
  ASSERT_EQ(daemon.deformation().nodes(), 10u);
  // What a driver adopting the segment now would check is refused (the area is 10 nodes long).
  EXPECT_THROW(MappedSegment::Adopt(dup(daemon.fd()), "the test"), Error);
  std::vector<std::int32_t> ids(10);
  std::vector<double> u(30);
  for (int i = 0; i < 10; ++i) ids[i] = 100 + i;
  for (int i = 0; i < 30; ++i) u[i] = 1e-3 * i - 0.01;
  ShmDeformationFrame written;
  written.frame = 7;
  written.utime = 123456;
  written.configuration_id = 3;
  written.in_contact = true;
  written.complete = false;
  written.nodes_per_axis = 13;
  written.spacing_m = 0.25 / 12;
  written.contact_node[0] = 6, written.contact_node[1] = 6, written.contact_node[2] = 0;
  // The driver scribbles over the newest index and both sequence words: the writer counts its
  // writes itself and still publishes whole frames.
  auto* words = reinterpret_cast<std::atomic<std::uint64_t>*>(
      reinterpret_cast<char*>(&driver.segment()) + sizeof(ShmSegment));
  words[0].store(static_cast<std::uint64_t>(INT64_MAX));
  words[ShmDeformationArea::kNewestWords].store(12345);  // frame 0's sequence, odd
  daemon.deformation().Write(0, written, ids.data(), u.data());
  written.frame = 8;
  u[29] = 0.5;
  daemon.deformation().Write(1, written, ids.data(), u.data());  // the other of the two frames
  std::vector<std::int32_t> ids_read(10);
  std::vector<double> u_read(30);
  ASSERT_TRUE(driver.deformation().Read(&meta, ids_read.data(), u_read.data()));
  EXPECT_EQ(meta.frame, 8);
  EXPECT_EQ(meta.utime, 123456);
  EXPECT_EQ(meta.configuration_id, 3);
  EXPECT_TRUE(meta.in_contact);
  EXPECT_FALSE(meta.complete);
  EXPECT_EQ(meta.nodes_per_axis, 13);
  EXPECT_EQ(meta.spacing_m, 0.25 / 12);
  EXPECT_EQ(meta.contact_node[0], 6);
  EXPECT_EQ(meta.contact_node[2], 0);
  EXPECT_EQ(meta.num_nodes, 10u);
  EXPECT_EQ(ids_read, ids);
  EXPECT_EQ(u_read, u);
}

TEST(SealedSegment, ADriverRefusesAHeaderWhoseSurfaceIsNotTheSegmentsSize) {
  MappedSegment daemon = MappedSegment::CreateSealed("hapticsim-test", 10);
  daemon.segment().header.deformation_nodes = 11;
  try {
    MappedSegment::Adopt(dup(daemon.fd()), "the server");
    ADD_FAILURE() << "a header claiming more surface than the segment holds was taken";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("other slot sizes"), std::string::npos) << e.what();
  }
}

TEST(ServiceSocket, ADriverMapsTheSegmentItsDaemonHandsOver) {
  const std::string path = testing::PrivateSocketPath();
  MappedSegment daemon = MappedSegment::CreateSealed("hapticsim-test");
  {
    FakeServer server(path,
                      [&](int socket) { SendMessage(socket, SessionGreeting(), daemon.fd()); });
    ShmDeviceClient driver(path);
    EXPECT_EQ(driver.daemon().pid, getpid());
    EXPECT_EQ(driver.daemon().uid, geteuid());
    driver.WriteInput(7, 0, {0.1, 0.1, 0.0});
    ShmDeviceInput written;
    ASSERT_TRUE(daemon.segment().inputs[0].Read(&written));
    EXPECT_EQ(written.seq, 7);
  }
  std::filesystem::remove_all(DirectoryOf(path));
}

TEST(ServiceSocket, ADriverRefusesASocketThatOthersCouldHavePutThere) {
  // A squatter's socket in a directory everybody can write, handing over a genuine-looking
  // segment: the driver never maps it.
  const std::string private_path = testing::PrivateSocketPath();
  const std::string directory = DirectoryOf(private_path);
  ASSERT_EQ(chmod(directory.c_str(), 01777), 0);
  MappedSegment squatter = MappedSegment::CreateSealed("squatter");
  {
    FakeServer server(private_path,
                      [&](int socket) { SendMessage(socket, SessionGreeting(), squatter.fd()); });
    const std::string verdict = DriverVerdict(private_path);
    EXPECT_NE(verdict.find("refusing the daemon at " + private_path), std::string::npos) << verdict;
    EXPECT_NE(verdict.find("(mode 1777) can be written by users other than its owner"),
              std::string::npos)
        << verdict;
  }
  // Group-writable is as bad.
  ASSERT_EQ(chmod(directory.c_str(), 0770), 0);
  {
    FakeServer server(private_path,
                      [&](int socket) { SendMessage(socket, SessionGreeting(), squatter.fd()); });
    EXPECT_NE(DriverVerdict(private_path).find("(mode 0770)"), std::string::npos);
  }
  std::filesystem::remove_all(directory);
}

// The squatter's better try: a directory of its own (0755, nobody else can write it) inside one
// everybody can write (sticky, like /tmp), e.g. /tmp/hsim before the user's `mkdir -p` ran. The
// socket, its directory and the server are all the squatter's; what gives it away is that the
// directory below the sticky one was made by another user than root or the driver's.
TEST(ServiceSocket, ADriverRefusesASocketInADirectoryAnotherUserMadeUnderAStickyOne) {
  if (geteuid() != 0) GTEST_SKIP() << "needs root to make a directory as another user";
  const std::string sticky = DirectoryOf(testing::PrivateSocketPath());
  ASSERT_EQ(chmod(sticky.c_str(), 01777), 0);
  const std::string squatted = sticky + "/hsim";
  ASSERT_EQ(mkdir(squatted.c_str(), 0755), 0);
  if (chown(squatted.c_str(), 65534, 65534) != 0) {
    std::filesystem::remove_all(sticky);
    GTEST_SKIP() << "uid 65534 is not mapped here (a user namespace)";
  }
  // Inside it, a root-owned private directory with the socket: every check on the socket's
  // own directory passes.
  const std::string inner = squatted + "/run";
  ASSERT_EQ(mkdir(inner.c_str(), 0700), 0);
  const std::string path = inner + "/hapticsimd.sock";
  MappedSegment squatter = MappedSegment::CreateSealed("squatter");
  {
    FakeServer server(path,
                      [&](int socket) { SendMessage(socket, SessionGreeting(), squatter.fd()); });
    const std::string verdict = DriverVerdict(path);
    EXPECT_NE(verdict.find(squatted + " is owned by uid 65534"), std::string::npos) << verdict;
  }
  // Owned by the driver's user instead (the user's own mkdir): trusted.
  ASSERT_EQ(chown(squatted.c_str(), geteuid(), getegid()), 0);
  {
    FakeServer server(path,
                      [&](int socket) { SendMessage(socket, SessionGreeting(), squatter.fd()); });
    EXPECT_EQ(DriverVerdict(path), "");
  }
  std::filesystem::remove_all(sticky);
}

TEST(ServiceSocket, ADriverRefusesASymbolicLinkOnThePath) {
  const std::string path = testing::PrivateSocketPath();
  const std::string directory = DirectoryOf(path);
  const std::string link = directory + "-link";
  std::filesystem::create_directory_symlink(directory, link);
  MappedSegment daemon = MappedSegment::CreateSealed("hapticsim-test");
  {
    FakeServer server(path,
                      [&](int socket) { SendMessage(socket, SessionGreeting(), daemon.fd()); });
    const std::string verdict = DriverVerdict(link + "/hapticsimd.sock");
    EXPECT_NE(verdict.find(link + " is a symbolic link"), std::string::npos) << verdict;
  }
  std::filesystem::remove(link);
  std::filesystem::remove_all(directory);
}

TEST(ServiceSocket, TheDaemonWillNotListenInADirectoryOthersCanWrite) {
  const std::string path = testing::PrivateSocketPath();
  const std::string directory = DirectoryOf(path);
  ASSERT_EQ(chmod(directory.c_str(), 01777), 0);
  EXPECT_NE(ListenerRefusal(path).find("(mode 1777) can be written by other users"),
            std::string::npos)
      << ListenerRefusal(path);
  std::filesystem::remove_all(directory);
}

TEST(ServiceSocket, ADriverRefusesASocketNotOwnedByTheProcessServingIt) {
  if (geteuid() != 0) GTEST_SKIP() << "needs root to give the socket to another user";
  const std::string path = testing::PrivateSocketPath();
  MappedSegment daemon = MappedSegment::CreateSealed("hapticsim-test");
  FakeServer server(path, [&](int socket) { SendMessage(socket, SessionGreeting(), daemon.fd()); });
  if (chown(path.c_str(), 65534, static_cast<gid_t>(-1)) != 0) {
    GTEST_SKIP() << "uid 65534 is not mapped here (a user namespace)";
  }
  const std::string verdict = DriverVerdict(path);
  EXPECT_NE(verdict.find("is owned by uid 65534 but served by uid 0"), std::string::npos)
      << verdict;
  std::filesystem::remove_all(DirectoryOf(path));
}

TEST(ServiceSocket, ADriverSaysWhyItWasRefusedOrWhatWasWrongWithTheAnswer) {
  const std::string path = testing::PrivateSocketPath();
  {
    FakeServer server(path, [](int socket) { SendMessage(socket, Refusal("go away")); });
    EXPECT_NE(DriverVerdict(path).find("refused this driver: go away"), std::string::npos);
  }
  {
    FakeServer server(path, [](int socket) { SendMessage(socket, "HELLO"); });
    EXPECT_NE(DriverVerdict(path).find("answered what hapticsimd does not say (0 descriptors)"),
              std::string::npos);
  }
  {
    FakeServer server(path, [](int) {});  // hangs up without a word
    EXPECT_NE(DriverVerdict(path).find("hung up without an answer"), std::string::npos);
  }
  EXPECT_NE(DriverVerdict(path).find("cannot connect to hapticsimd at " + path),
            std::string::npos);  // nobody listens any more
  std::filesystem::remove_all(DirectoryOf(path));
}

TEST(ServiceSocket, TheDaemonAdmitsRootItsOwnUserAndItsGroupOnly) {
  PeerIdentity peer;
  peer.pid = 1234;
  peer.uid = 1000;
  peer.gid = 1000;
  EXPECT_EQ(PeerRefusal(peer, 1000, 2000, "hapticsim"), "");  // the daemon's own user
  peer.uid = 0;
  EXPECT_EQ(PeerRefusal(peer, 999, 2000, "hapticsim"), "");  // root
  peer.uid = 1001;
  EXPECT_NE(PeerRefusal(peer, 999, 2000, "hapticsim")
                .find("pid 1234 (uid 1001) is not in group hapticsim: add that user"),
            std::string::npos);
  peer.gid = 2000;
  EXPECT_EQ(PeerRefusal(peer, 999, 2000, "hapticsim"), "");  // primary group
  peer.gid = 1001;
  peer.groups = {5, 2000};
  EXPECT_EQ(PeerRefusal(peer, 999, 2000, "hapticsim"), "");  // supplementary group
}

TEST(ServiceSocket, TheDaemonReplacesADeadDaemonsSocketButNotALiveOneOrAFile) {
  const std::string path = testing::PrivateSocketPath();
  { ServiceListener stopped(path, ""); }  // a daemon that stops removes its socket
  ASSERT_FALSE(std::filesystem::exists(path));
  {
    ServiceListener live(path, "");
    EXPECT_NE(ListenerRefusal(path).find("another hapticsimd already serves it"),
              std::string::npos);
    struct stat info {};
    ASSERT_EQ(stat(path.c_str(), &info), 0);
    EXPECT_EQ(info.st_mode & 0777, 0660u);
  }
  {
    const int left = socket(AF_UNIX, SOCK_SEQPACKET, 0);
    sockaddr_un address{};
    address.sun_family = AF_UNIX;
    std::snprintf(address.sun_path, sizeof address.sun_path, "%s", path.c_str());
    ASSERT_EQ(bind(left, reinterpret_cast<sockaddr*>(&address), sizeof address), 0);
    close(left);  // bound, never listening: what a killed daemon leaves
    ServiceListener after_crash(path, "");
  }
  std::ofstream(path) << "not a socket";
  EXPECT_NE(ListenerRefusal(path).find("a file that is not a socket is in the way"),
            std::string::npos);
  std::filesystem::remove_all(DirectoryOf(path));
}

}  // namespace
}  // namespace hapticsim::shm
