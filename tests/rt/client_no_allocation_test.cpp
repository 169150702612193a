// The C API's real-time calls (hapticsim_send_pose, _read_force, _is_live, _read_status,
// _read_deformation) never touch the heap, measured on a session with a real daemon (LCM off: no
// network) while it answers a press; the deformed surface read through it has the touched node
// where the tool is; and the session follows a restarted daemon (hapticsim_reconnect).
#include <gtest/gtest.h>
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "hapticsim_client.h"
#include "tests/support/allocation_counter.hpp"
#include "tests/support/daemon_harness.hpp"
#include "tests/support/private_socket.hpp"
#include "tests/support/run_command.hpp"

namespace {

std::int64_t NowNs() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

TEST(ClientCApi, TheRealTimeCallsNeverAllocateAndASessionFollowsARestartedDaemon) {
  const std::string socket = hapticsim::testing::PrivateSocketPath();
  const std::string config = ::testing::TempDir() + "client_c_api.toml";
  std::ofstream(config) << "[lcm]\nenabled = false\n[control]\nenabled = false\n"
                        << "[shm]\nenabled = true\nsocket = \"" << socket << "\"\n";
  hapticsim::testing::BackgroundProcess daemon({HAPTICSIMD_PATH, "--config", config},
                                               ::testing::TempDir() + "client_c_api.log");
  ASSERT_NO_FATAL_FAILURE(hapticsim::testing::WaitUntilServing(daemon));
  char why[512];
  hapticsim_client* client = hapticsim_connect(socket.c_str(), why, sizeof why);
  ASSERT_NE(client, nullptr) << why;

  // The default cube's surface: 13³ − 11³ nodes.
  const std::int32_t nodes = hapticsim_deformation_nodes(client);
  ASSERT_EQ(nodes, 13 * 13 * 13 - 11 * 11 * 11);
  std::vector<std::int32_t> ids(static_cast<size_t>(nodes));
  std::vector<double> displacement(3 * ids.size());
  hapticsim_deformation surface{};
  std::size_t allocations = 0;
  int forces = 0, live = 0, in_contact = 0, reads = 0;
  std::int64_t last_frame = -1, distinct_frames = 0;
  for (int seq = 1; seq <= 600; ++seq) {
    const double position[3] = {0.125, 0.125, seq < 100 ? -0.002 : 0.004};
    hapticsim_force force{};
    hapticsim_status status{};
    bool read = false;
    {
      hapticsim::testing::ScopedAllocationCount count;
      hapticsim_send_pose(client, seq, NowNs() / 1000, position);
      read = hapticsim_read_force(client, &force) == 1;
      live += hapticsim_is_live(client, NowNs());
      hapticsim_read_status(client, &status);
      if (seq % 10 == 0) {
        reads +=
            hapticsim_read_deformation(client, &surface, ids.data(), displacement.data(), nodes);
        distinct_frames += surface.frame != last_frame;
        last_frame = surface.frame;
      }
      allocations += count.count();
    }
    forces += read;
    if (read && (force.flags & HAPTICSIM_FLAG_IN_CONTACT)) ++in_contact;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  EXPECT_EQ(allocations, 0u);
  // The calls did their work: the daemon answered, live, and felt the press.
  EXPECT_GT(forces, 500);
  EXPECT_GT(live, 500);
  EXPECT_GT(in_contact, 100) << daemon.Log();
  hapticsim_status status;
  ASSERT_EQ(hapticsim_read_status(client, &status), 0);
  EXPECT_EQ(status.daemon_pid, daemon.pid());
  EXPECT_EQ(status.poses_sent, 600);

  // The deformed surface (60 frames per second by default): the touched node (6, 6, 0) where the
  // tool held it, 4 mm in, for the last 0.5 s.
  // Read every 10 ms, a frame every 16.7 ms: most reads see a frame the last did not.
  EXPECT_GT(reads, 50) << "reads that found a frame, of 60";
  EXPECT_GT(distinct_frames, 25) << "frames seen, of the 36 the daemon made meanwhile";
  ASSERT_EQ(hapticsim_read_deformation(client, &surface, ids.data(), displacement.data(), nodes),
            1);
  EXPECT_EQ(surface.num_nodes, nodes);
  EXPECT_EQ(surface.nodes_per_axis, 13);
  EXPECT_DOUBLE_EQ(surface.spacing_m, 0.25 / 12);
  EXPECT_EQ(surface.in_contact, 1);
  EXPECT_GE(surface.frame, 0);
  const std::int32_t touched = (6 * 13 + 6) * 13 + 0;
  const auto at = std::lower_bound(ids.begin(), ids.end(), touched);
  ASSERT_TRUE(at != ids.end() && *at == touched);
  const size_t i = static_cast<size_t>(at - ids.begin());
  EXPECT_NEAR(displacement[3 * i + 2], 0.004, 5e-4);
  EXPECT_LT(std::abs(displacement[3 * i]) + std::abs(displacement[3 * i + 1]), 1e-4);
  // Arrays too small, or nowhere to put the facts: refused, nothing written.
  std::vector<std::int32_t> small(static_cast<size_t>(nodes - 1), -7);
  EXPECT_EQ(hapticsim_read_deformation(client, &surface, small.data(), nullptr, nodes - 1), -1);
  EXPECT_TRUE(std::all_of(small.begin(), small.end(), [](std::int32_t id) { return id == -7; }));
  EXPECT_EQ(hapticsim_read_deformation(client, nullptr, nullptr, nullptr, 0), -1);
  EXPECT_EQ(hapticsim_read_deformation(client, &surface, nullptr, nullptr, 0), 1);

  // The daemon stops: not live within 20 ms, its pid cleared; a new one at the same socket is
  // reached by hapticsim_reconnect, and answers.
  daemon.Signal(SIGTERM);
  EXPECT_EQ(daemon.Wait(5), 0) << daemon.Log();
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_EQ(hapticsim_is_live(client, NowNs()), 0);
  ASSERT_EQ(hapticsim_read_status(client, &status), 0);
  EXPECT_EQ(status.daemon_running, 0);
  EXPECT_EQ(hapticsim_reconnect(client), 0);  // nobody there yet: the old session stays
  hapticsim::testing::BackgroundProcess restarted({HAPTICSIMD_PATH, "--config", config},
                                                  ::testing::TempDir() + "client_c_api_2.log");
  ASSERT_NO_FATAL_FAILURE(hapticsim::testing::WaitUntilServing(restarted));
  EXPECT_EQ(hapticsim_reconnect(client), 1) << restarted.Log();
  int live_again = 0;
  for (int seq = 601; seq <= 700; ++seq) {
    const double position[3] = {0.125, 0.125, -0.002};
    hapticsim_send_pose(client, seq, NowNs() / 1000, position);
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
    live_again += hapticsim_is_live(client, NowNs());
  }
  EXPECT_GT(live_again, 50);
  ASSERT_EQ(hapticsim_read_status(client, &status), 0);
  EXPECT_EQ(status.daemon_pid, restarted.pid());
  hapticsim_disconnect(client);
  restarted.Signal(SIGTERM);
  EXPECT_EQ(restarted.Wait(5), 0) << restarted.Log();
}

}  // namespace
