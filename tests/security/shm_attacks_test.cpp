// Hostile neighbours on the shared-memory interface (issue "Hostile neighbours", points 1, 3, 5):
// a real hapticsimd, attacked by a separate local process. Each test asserts that the attack is
// refused and counted (status over a real LCM bus, in the private network namespace the suite runs
// in), that the daemon keeps serving a real driver, and that the primary misses no more deadlines
// during the attack than in a quiet stretch of the same length just before it.
#include <fcntl.h>
#include <grp.h>
#include <gtest/gtest.h>
#include <sys/mman.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <string>
#include <thread>

#include "ipc/service_socket.hpp"
#include "ipc/shm_device_client.hpp"
#include "tests/security/hostile_neighbour.hpp"
#include "tests/support/private_socket.hpp"
#include "tests/support/run_command.hpp"

namespace hapticsim {
namespace {

using security::Clock;
using security::ExitStatusOf;
using security::HostileNeighbour;
using security::kEdge;
using security::kWindow;
using security::MissBound;
using security::Spawn;

// An attacker's raw connection: connects to `path` and takes whatever descriptor comes with the
// answer (-1: none), keeping the connection in *connection. Raw system calls only: the attacker
// does not use the client library's checks.
int TakeSegment(const std::string& path, int* connection, std::string* answer = nullptr) {
  *connection = socket(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0);
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  std::snprintf(address.sun_path, sizeof address.sun_path, "%s", path.c_str());
  if (connect(*connection, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0) return -1;
  char text[256] = {};
  iovec part{text, sizeof text - 1};
  alignas(cmsghdr) char control[CMSG_SPACE(sizeof(int))];
  msghdr message{};
  message.msg_iov = &part;
  message.msg_iovlen = 1;
  message.msg_control = control;
  message.msg_controllen = sizeof control;
  const ssize_t n = recvmsg(*connection, &message, 0);
  if (answer && n > 0) answer->assign(text, static_cast<std::size_t>(n));
  cmsghdr* header = CMSG_FIRSTHDR(&message);
  if (n <= 0 || !header || header->cmsg_type != SCM_RIGHTS) return -1;
  int fd;
  std::memcpy(&fd, CMSG_DATA(header), sizeof fd);
  return fd;
}

// Point 1: a driver that truncates its segment (before: the daemon died of SIGBUS at its next
// write), grows it, tries to add or remove seals, or scribbles over all of it.
TEST_F(HostileNeighbour, ADriverCannotResizeItsSegmentAndScribblingOnItHarmsNothing) {
  const std::int64_t quiet = MissesOver(Quiet);
  pid_t attacker = -1;
  const std::int64_t attacked = MissesOver([&] {
    attacker = Spawn([&] {
      int connection = -1;
      const int fd = TakeSegment(socket_, &connection);
      if (fd < 0) return 10;  // no segment handed over
      int succeeded = 0;
      if (ftruncate(fd, 0) == 0) succeeded |= 1;
      if (ftruncate(fd, 1 << 20) == 0) succeeded |= 2;
      if (fallocate(fd, 0, 0, 1 << 20) == 0) succeeded |= 4;
      if (fcntl(fd, F_ADD_SEALS, F_SEAL_WRITE) == 0) succeeded |= 8;
      struct stat info {};
      fstat(fd, &info);
      void* memory = mmap(nullptr, info.st_size, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
      if (memory == MAP_FAILED) return 11;
      // Every byte, over and over, for the attacked window: indexes, slots, the header.
      const auto end = Clock::now() + kWindow;
      for (unsigned char byte = 0; Clock::now() < end; byte += 37) {
        std::memset(memory, byte, info.st_size);
        std::this_thread::sleep_for(std::chrono::microseconds(200));
      }
      return succeeded;
    });
    std::this_thread::sleep_for(kWindow + std::chrono::milliseconds(100));
  });
  EXPECT_EQ(ExitStatusOf(attacker), 0) << "1 truncate, 2 grow, 4 allocate, 8 seal succeeded";
  ASSERT_TRUE(daemon_->running()) << daemon_->Log();
  EXPECT_LE(attacked, MissBound(quiet)) << "quiet: " << quiet;
  const auto status = monitor_.LastStatus();
  ASSERT_TRUE(status);
  EXPECT_EQ(status->shm_sessions, 1);
  ExpectADriverIsServed();
}

// Point 1: "no client action on the segment can change what another session sees". While one
// driver holds the session another is refused and counted; a driver whose session ended keeps
// a mapping that no longer reaches the daemon.
TEST_F(HostileNeighbour, ADriverCannotTakeOverOrReachIntoAnotherDriversSession) {
  // The first driver, a separate process, takes the session and leaves it, keeping its mapping.
  int ready[2];
  ASSERT_EQ(pipe(ready), 0);
  const pid_t former = Spawn([&] {
    int connection = -1;
    const int fd = TakeSegment(socket_, &connection);
    if (fd < 0) return 10;
    auto* segment = static_cast<shm::ShmSegment*>(
        mmap(nullptr, sizeof(shm::ShmSegment), PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0));
    close(connection);  // the session ends; the mapping stays
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    if (write(ready[1], "x", 1) != 1) return 12;
    // From then on, 2 cm inside the object through the old mapping, every millisecond.
    const auto end = Clock::now() + 3 * kWindow;
    for (std::int64_t seq = 1; Clock::now() < end; ++seq) {
      shm::ShmDeviceInput input;
      input.seq = seq;
      input.position_m[0] = input.position_m[1] = kEdge / 2;
      input.position_m[2] = 0.02;
      shm::WriteDeviceInput(*segment, input);
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    return segment->header.daemon_pid.load() == 0 ? 0 : 13;  // told the daemon is gone
  });
  char byte;
  ASSERT_EQ(read(ready[0], &byte, 1), 1);

  // The next driver holds the tool above the surface: it must feel nothing of the 2 cm.
  shm::ShmDeviceClient driver(socket_);
  double largest_force = 0;
  std::int64_t seq = 1;
  auto hold_above = [&] {
    const auto end = Clock::now() + kWindow;
    while (Clock::now() < end) {
      driver.WriteInput(seq++, 0, {kEdge / 2, kEdge / 2, -0.002});
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
      shm::ShmForceOutput out;
      if (driver.ReadForce(&out)) largest_force = std::max(largest_force, std::abs(out.force_n[2]));
    }
  };
  const std::int64_t quiet = MissesOver(hold_above);
  const std::int64_t attacked = MissesOver([&] {
    // A third process tries to take the session while the driver holds it.
    std::string answer;
    const pid_t intruder = Spawn([&] {
      int connection = -1;
      if (TakeSegment(socket_, &connection, &answer) >= 0) return 1;  // handed a segment
      return answer.find("holds the session; one driver at a time") != std::string::npos ? 0 : 2;
    });
    hold_above();
    EXPECT_EQ(ExitStatusOf(intruder), 0) << "1: the intruder was handed a segment; 2: refused "
                                            "without saying why (or not connected at all)";
  });
  EXPECT_EQ(ExitStatusOf(former), 0) << "10/12: no session; 13: the old mapping was not told";
  EXPECT_EQ(largest_force, 0.0) << "the former driver's input reached the daemon";
  ASSERT_TRUE(daemon_->running()) << daemon_->Log();
  EXPECT_LE(attacked, MissBound(quiet)) << "quiet: " << quiet;
  ASSERT_TRUE(monitor_.WaitForStatus([](const status_t& s) { return s.shm_refused == 1; }, 2))
      << daemon_->Log();
  EXPECT_EQ(monitor_.LastStatus()->shm_sessions, 2);
  EXPECT_NE(daemon_->Log().find("holds the session; one driver at a time"), std::string::npos)
      << daemon_->Log();
}

// Point 1, the credentials: even with the socket opened to everyone by mistake (mode 0666), a
// user outside shm.group is refused by the daemon, which asks the kernel who connected.
TEST_F(HostileNeighbour, AUserOutsideTheGroupIsRefusedEvenWhenTheSocketIsOpenToAll) {
  if (geteuid() != 0) GTEST_SKIP() << "needs root, to be another user";
  ASSERT_EQ(chmod(socket_.c_str(), 0666), 0);
  ASSERT_EQ(chmod(std::filesystem::path(socket_).parent_path().c_str(), 0755), 0);
  const std::int64_t quiet = MissesOver(Quiet);
  std::int64_t attacked = 0;
  const int outsider_status = AttackAsAnotherUser(
      [&] {
        int connection = -1;
        std::string answer;
        if (TakeSegment(socket_, &connection, &answer) >= 0) return 1;
        return answer.find("(uid 65534) is not in group") != std::string::npos ? 0 : 2;
      },
      &attacked);
  if (outsider_status == kNoOtherUser)
    GTEST_SKIP() << "uid 65534 is not available here (user namespace)";
  EXPECT_EQ(outsider_status, 0) << "1: handed a segment; 2: refused without saying why";
  ASSERT_TRUE(daemon_->running()) << daemon_->Log();
  EXPECT_LE(attacked, MissBound(quiet)) << "quiet: " << quiet;
  ASSERT_TRUE(monitor_.WaitForStatus([](const status_t& s) { return s.shm_refused == 1; }, 2));
  EXPECT_EQ(monitor_.LastStatus()->shm_sessions, 0);
  ExpectADriverIsServed();
}

// Point 3, through shared memory: a driver process writes numbers at the edges — a seq near 2⁶²
// (the tool tip used to go NaN), NaN, infinite and huge positions — between ordinary inputs. Each
// is refused and counted, no force is non-finite, and the ordinary press goes on being felt.
TEST_F(HostileNeighbour, ADriversNumbersAtTheEdgesAreRefusedCountedAndNeverReachTheForce) {
  // The same press in both windows — the quiet one without the numbers at the edges — so the
  // comparison is of the attack alone: a press wakes the regions, which idle ones do not pay for.
  auto press = [&](bool at_the_edges) {
    pid_t driver = -1;
    const std::int64_t misses = MissesOver([&] {
      driver = Spawn([&] {
        try {
          shm::ShmDeviceClient client(socket_);
          const double wild[][3] = {{NAN, kEdge / 2, 0.001},
                                    {kEdge / 2, INFINITY, 0.001},
                                    {kEdge / 2, kEdge / 2, 1e300},
                                    {-1e9, kEdge / 2, 0.001}};
          std::int64_t seq = 1, nonfinite = 0, pushing = 0;
          const auto end = Clock::now() + kWindow;
          for (int n = 0; Clock::now() < end; ++n, ++seq) {
            const double z = n < 50 ? -0.002 : std::min(0.005, 1e-5 * (n - 50));
            client.WriteInput(seq, 0, {kEdge / 2, kEdge / 2, z});
            if (at_the_edges && n % 10 == 5) {  // every tenth period, something at an edge
              const auto& w = wild[(n / 10) % 4];
              client.WriteInput(n % 20 == 5 ? (std::int64_t{1} << 62) : ++seq, 0,
                                {w[0], w[1], w[2]});
            }
            std::this_thread::sleep_for(std::chrono::milliseconds(1));
            shm::ShmForceOutput out;
            if (!client.ReadForce(&out)) continue;
            if (!std::isfinite(out.force_n[0] + out.force_n[1] + out.force_n[2])) ++nonfinite;
            if (out.force_n[2] < -0.2) ++pushing;
          }
          return nonfinite == 0 && pushing > 100 ? 0 : 1;
        } catch (const std::exception&) {
          return 2;
        }
      });
      std::this_thread::sleep_for(kWindow + std::chrono::milliseconds(200));
    });
    EXPECT_EQ(ExitStatusOf(driver), 0) << "1: a non-finite force, or the press was not felt";
    std::this_thread::sleep_for(std::chrono::milliseconds(300));  // the session ends
    return misses;
  };
  std::int64_t quiet = press(false);
  std::int64_t attacked = press(true);
  std::printf("primary deadline misses: %lld pressing, %lld pressing with numbers at the edges\n",
              static_cast<long long>(quiet), static_cast<long long>(attacked));
  if (attacked > MissBound(quiet)) {
    // One hiccup of a machine shared with a whole suite is not the attack's: look again (a
    // full-suite run once saw 117 misses attacked after 6 quiet; alone, 0–3 in every window).
    quiet = press(false);
    attacked = press(true);
    std::printf("looked again: %lld pressing, %lld pressing with numbers at the edges\n",
                static_cast<long long>(quiet), static_cast<long long>(attacked));
  }
  ASSERT_TRUE(daemon_->running()) << daemon_->Log();
  EXPECT_LE(attacked, MissBound(quiet)) << "quiet: " << quiet;
  ASSERT_TRUE(monitor_.WaitForStatus([](const status_t& s) { return s.inputs_rejected >= 50; }, 2))
      << daemon_->Log();
  EXPECT_NE(daemon_->Log().find("device input rejected"), std::string::npos);
  ExpectADriverIsServed();
}

// Point 5: a process that sets up a socket before the daemon, where others can write, and hands
// out a segment with a force of its own in it. The driver refuses it and says why; it never
// reads that force.
TEST(Squatting, ADriverRefusesASocketAnotherUserCouldHavePutThereAndSaysWhy) {
  const std::string path = testing::PrivateSocketPath();
  const std::string directory = std::filesystem::path(path).parent_path();
  ASSERT_EQ(chmod(directory.c_str(), 01777), 0);  // like /tmp
  int ready[2];
  ASSERT_EQ(pipe(ready), 0);
  const pid_t squatter = Spawn([&] {
    // Raw calls, as a squatter makes them (hapticsimd's own listener refuses such a directory).
    shm::UniqueFd listener(socket(AF_UNIX, SOCK_SEQPACKET | SOCK_NONBLOCK | SOCK_CLOEXEC, 0));
    sockaddr_un address{};
    address.sun_family = AF_UNIX;
    std::snprintf(address.sun_path, sizeof address.sun_path, "%s", path.c_str());
    if (bind(listener.get(), reinterpret_cast<sockaddr*>(&address), sizeof address) != 0 ||
        listen(listener.get(), 8) != 0) {
      return 2;
    }
    shm::MappedSegment forged = shm::MappedSegment::CreateSealed("hapticsim");
    shm::ShmForceOutput push;
    push.period = 0;
    push.force_n[2] = -20.0;  // a motor pushing a hand
    forged.segment().outputs[0].Write(push);
    forged.segment().newest_output.store(0);
    if (write(ready[1], "x", 1) != 1) return 1;
    const auto end = Clock::now() + std::chrono::seconds(3);
    while (Clock::now() < end) {
      shm::UniqueFd connection(accept4(listener.get(), nullptr, nullptr, SOCK_CLOEXEC));
      if (connection) shm::SendMessage(connection.get(), shm::SessionGreeting(), forged.fd());
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    return 0;
  });
  char byte;
  ASSERT_EQ(read(ready[0], &byte, 1), 1);
  const auto result =
      testing::RunCommand({HAPTICSIM_SHM_CLIENT_PATH, "--socket", path, "--duration", "0.1"});
  EXPECT_EQ(result.exit_status, 2) << result.out;
  EXPECT_NE(result.err.find("refusing the daemon at " + path), std::string::npos) << result.err;
  EXPECT_NE(result.err.find("can be written by users other than its owner"), std::string::npos)
      << result.err;
  EXPECT_EQ(result.out, "") << "the forged force was read";
  kill(squatter, SIGTERM);
  ExitStatusOf(squatter);
  std::filesystem::remove_all(directory);
}

}  // namespace
}  // namespace hapticsim
