// The deformed surface out of a running hapticsimd (deformation_t on LCM), end to end on a real
// LCM bus inside the private network namespace the test binary runs in
// (tests/support/in_private_netns.sh). Checked against what the test itself drives: the tool's
// depth at the touched node, a surface at rest before the touch, and the frame rate asked for.
#include <gtest/gtest.h>
#include <signal.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <lcm/lcm-cpp.hpp>
#include <mutex>
#include <thread>
#include <utility>
#include <vector>

#include "core/fem/static_solver.hpp"
#include "core/scene/scene_model.hpp"
#include "core/scene/scene_toml.hpp"
#include "hapticsim/deformation_t.hpp"
#include "hapticsim/force_feedback_t.hpp"
#include "tests/support/box_stl.hpp"
#include "tests/support/daemon_harness.hpp"
#include "tests/support/private_socket.hpp"
#include "tests/support/process_threads.hpp"
#include "tests/support/run_command.hpp"

namespace hapticsim {
namespace {

using Clock = std::chrono::steady_clock;

// Every deformation_t on HAPTIC_DEFORMATION, with when it arrived.
class DeformationListener {
 public:
  DeformationListener() : lcm_("udpm://239.255.76.67:7667?ttl=0") {
    EXPECT_TRUE(lcm_.good());
    lcm_.subscribe("HAPTIC_DEFORMATION", &DeformationListener::On, this)->setQueueCapacity(1000);
    thread_ = std::thread([this] {
      while (!stop_) lcm_.handleTimeout(10);
    });
  }
  ~DeformationListener() {
    stop_ = true;
    thread_.join();
  }
  struct Received {
    deformation_t message;
    Clock::time_point at;
  };
  std::vector<Received> Frames() {
    std::lock_guard lock(mutex_);
    return frames_;
  }

 private:
  void On(const lcm::ReceiveBuffer*, const std::string&, const deformation_t* d) {
    std::lock_guard lock(mutex_);
    frames_.push_back({*d, Clock::now()});
  }
  lcm::LCM lcm_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
  std::mutex mutex_;
  std::vector<Received> frames_;
};

// The displacement of node `id` in frame `d`, given the ids last sent; nullopt if it has none.
std::optional<std::array<float, 3>> NodeDisplacement(const deformation_t& d,
                                                     const std::vector<int32_t>& ids, int32_t id) {
  const auto it = std::lower_bound(ids.begin(), ids.end(), id);
  if (it == ids.end() || *it != id || ids.size() != static_cast<size_t>(d.num_nodes)) {
    return std::nullopt;
  }
  const auto& row = d.displacement_m[it - ids.begin()];
  return std::array<float, 3>{row[0], row[1], row[2]};
}

// The config of a hapticsimd on the test's LCM bus, publishing the deformation at 60 Hz, serving
// `scene_path` (none: the built-in cube).
std::string WriteDaemonConfig(const std::string& dir, const std::string& control,
                              const std::string& scene_path = "") {
  const std::string config = dir + "/hapticsimd.toml";
  std::ofstream out(config);
  out << "[lcm]\nurl = \"udpm://239.255.76.67:7667?ttl=0\"\n"
      << "[control]\nsocket = \"" << control << "\"\n"
      << "[deformation]\nrate_hz = 60\n";
  if (!scene_path.empty()) out << "[scene]\nfile = \"" << scene_path << "\"\n";
  return config;
}

// A device: one input a millisecond on absolute sleeps, `tip(seq)` for seq = 1 … count.
void SendEveryMillisecond(testing::Client& client, std::int64_t count,
                          const std::function<std::array<double, 3>(std::int64_t)>& tip) {
  auto next = Clock::now();
  for (std::int64_t seq = 1; seq <= count; ++seq) {
    const std::array<double, 3> p = tip(seq);
    client.Send(seq, p[0], p[1], p[2]);
    next += std::chrono::milliseconds(1);
    std::this_thread::sleep_until(next);
  }
}

TEST(HapticsimdDeformation, ThePressedSurfaceComesOutAtItsRateWithTheToolsDepthAtTheTouchedNode) {
  const std::string dir = ::testing::TempDir() + "hapticsimd_deformation";
  std::filesystem::create_directories(dir);
  const std::string control = testing::PrivateSocketPath();
  const std::string config = WriteDaemonConfig(dir, control);
  testing::BackgroundProcess daemon({HAPTICSIMD_PATH, "--config", config}, dir + "/daemon.log");
  DeformationListener listener;
  testing::Client client;
  testing::WaitUntilServing(daemon);
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));  // asleep at rest: frames still
  // The frames give way to the region threads where the CPUs are short: their thread runs at
  // nice 10 (or the daemon's own, if nicer), the regions' at the daemon's own.
  const int own = testing::NiceOf(daemon.pid(), daemon.pid());
  ASSERT_LT(own, 20);
  for (const auto& [thread, nice] : {std::pair<const char*, int>{"hsim-deform", std::max(own, 10)},
                                     {"hsim-primary", own},
                                     {"hsim-region1", own}}) {
    const pid_t tid = testing::ThreadOf(daemon.pid(), thread);
    ASSERT_GT(tid, 0) << "no thread named " << thread;
    EXPECT_EQ(testing::NiceOf(daemon.pid(), tid), nice) << thread;
  }

  // The default cube: 13 nodes per axis, the touched node (6, 6, 0) in the middle of the front
  // face; pressing in is +z. 1 cm in over 0.5 s, then held for 0.8 s.
  constexpr double kEdge = 0.25, kDepth = 0.01;
  constexpr int n = 13;
  // A support (a back corner, held at zero) and the front face's corner beside the touched node.
  constexpr int32_t kTouched = (6 * n + 6) * n + 0, kSupport = (0 * n + 0) * n + (n - 1),
                    kFrontCorner = 0;
  const auto press_start = Clock::now();
  SendEveryMillisecond(client, 1600, [&](std::int64_t seq) {
    const double z = seq <= 300 ? -0.005 : kDepth * std::min(1.0, (seq - 300) / 500.0);
    return std::array<double, 3>{kEdge / 2, kEdge / 2, z};
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  const std::vector<DeformationListener::Received> frames = listener.Frames();
  // The frames counted in the press are those received from its start until now: 1.7 s if this
  // thread sent on time, longer on a busy machine (the daemon publishes on meanwhile).
  const double press_s = std::chrono::duration<double>(Clock::now() - press_start).count();
  daemon.Signal(SIGTERM);
  EXPECT_EQ(daemon.Wait(5), 0) << daemon.Log();
  std::filesystem::remove_all(std::filesystem::path(control).parent_path());
  ASSERT_GT(frames.size(), 100u) << daemon.Log();

  // Ids: all of them in the first frame, again at least every second, ascending; the surface of
  // a 13³ lattice has 13³ − 11³ nodes.
  const deformation_t& first = frames.front().message;
  ASSERT_EQ(first.num_ids, n * n * n - 11 * 11 * 11);
  EXPECT_EQ(first.nodes_per_axis, n);
  EXPECT_DOUBLE_EQ(first.spacing_m, kEdge / (n - 1));
  EXPECT_TRUE(std::is_sorted(first.node_ids.begin(), first.node_ids.end()));
  std::vector<int32_t> ids;
  Clock::time_point ids_at = frames.front().at;
  double largest_id_gap_s = 0, largest_latency_ms = 0;
  int at_rest_before = 0, frames_in_press = 0, held = 0;
  int64_t lost = 0;
  float touched_held_z = 0;
  for (size_t i = 0; i < frames.size(); ++i) {
    const deformation_t& d = frames[i].message;
    if (d.num_ids > 0) {
      ids = d.node_ids;
      largest_id_gap_s =
          std::max(largest_id_gap_s, std::chrono::duration<double>(frames[i].at - ids_at).count());
      ids_at = frames[i].at;
    }
    if (i > 0) lost += d.frame - frames[i - 1].message.frame - 1;
    ASSERT_EQ(d.num_nodes, first.num_ids);
    largest_latency_ms = std::max(largest_latency_ms, static_cast<double>(d.latency_ms));
    float largest = 0;
    for (const auto& row : d.displacement_m) {
      for (float v : row) {
        ASSERT_TRUE(std::isfinite(v));
        largest = std::max(largest, std::abs(v));
      }
    }
    const double since_press = std::chrono::duration<double>(frames[i].at - press_start).count();
    if (since_press < 0) {
      EXPECT_LT(largest, 1e-6) << "the surface moved before anything touched it";
      EXPECT_FALSE(d.in_contact);
      ++at_rest_before;
      continue;
    }
    ++frames_in_press;
    // Held at 1 cm for the last 0.8 s: from 0.9 s (the regions have followed the tip) to 1.55 s.
    if (since_press > 0.9 && since_press < 1.55) {
      const auto touched = NodeDisplacement(d, ids, kTouched);
      const auto support = NodeDisplacement(d, ids, kSupport);
      const auto corner = NodeDisplacement(d, ids, kFrontCorner);
      ASSERT_TRUE(touched && support && corner);
      EXPECT_TRUE(d.in_contact) << "frame " << d.frame << ", " << since_press
                                << " s into the press";
      // The touched node is where the tool is (the daemon follows the tip within a few periods).
      EXPECT_NEAR((*touched)[2], kDepth, 5e-4) << "frame " << d.frame;
      EXPECT_LT(std::abs((*touched)[0]) + std::abs((*touched)[1]), 1e-4);
      // The support stays where it is; the front face's corner, 18 cm from the tool, is drawn
      // in far less than the touched node.
      for (int c = 0; c < 3; ++c) EXPECT_EQ((*support)[c], 0.0f) << c;
      EXPECT_TRUE(d.complete);
      EXPECT_LT(std::abs((*corner)[2]), 0.5 * kDepth);
      EXPECT_GT((*corner)[2], 0.0f) << "the whole cube is drawn in by the press";
      touched_held_z = (*touched)[2];
      ++held;
    }
  }
  EXPECT_GT(at_rest_before, 30) << "frames while asleep before the press";
  EXPECT_GT(held, 30);
  EXPECT_NEAR(touched_held_z, kDepth, 5e-4);
  EXPECT_LE(largest_id_gap_s, 1.0 + 0.1);
  // 60 frames per second: over the 1.6 s press and the 0.1 s after it, 102; the daemon may lose a
  // few on a busy host.
  EXPECT_NEAR(frames_in_press / press_s, 60.0, 6.0)
      << frames_in_press << " frames in " << press_s << " s";
  EXPECT_LE(lost, static_cast<int64_t>(frames.size() / 50)) << "frames lost on the way";
  EXPECT_LT(largest_latency_ms, 40.0);
  std::printf(
      "deformation: %zu frames, %d in the press, touched node held at %.5f m, largest "
      "latency %.2f ms, ids every %.2f s at most, %lld lost\n",
      frames.size(), frames_in_press, touched_held_z, largest_latency_ms, largest_id_gap_s,
      static_cast<long long>(lost));
}

// A block from a file — 6 × 4 × 3 cm drawn as an STL, voxelised at 1 cm (7 × 5 × 4 nodes), its back
// face held — served by a real hapticsimd: the deformation's ids decode with its one node count
// to the block's own surface, the touched node goes where the tool is, and the force on the hand
// settles to the static solution of the same scene (solved here, not by the daemon).
TEST(HapticsimdDeformation, ABlockFromAFileIsServedOnItsOwnLattice) {
  const std::string dir = ::testing::TempDir() + "hapticsimd_block";
  std::filesystem::create_directories(dir);
  testing::WriteBoxStl(dir + "/block.stl", {0.06, 0.04, 0.03});
  const std::string scene_path = dir + "/block.toml";
  std::ofstream(scene_path) << "[geometry]\nfile = \"block.stl\"\nspacing_m = 0.01\n"
                            << "[[material]]\nlabel = 1\n"
                            << "[[support]]\nplane_point = [0.0, 0.0, 0.03]\n"
                            << "plane_normal = [0.0, 0.0, 1.0]\n"
                            // (the default primary size, 3 nodes around the contact, would take
                            // the whole block and leave no secondary region)
                            << "[adaptivity]\nprimary_size = 2\nsecondary_lod = 1\n"
                            << "secondary_rate = 1000.0\n";
  const std::string control = testing::PrivateSocketPath();
  const std::string config = WriteDaemonConfig(dir, control, scene_path);
  testing::BackgroundProcess daemon({HAPTICSIMD_PATH, "--config", config}, dir + "/daemon.log");
  DeformationListener listener;
  testing::Client client;
  testing::WaitUntilServing(daemon);
  // The default contact: the front-most node of the middle column, (3, 2, 0) at (3, 2, 0) cm.
  // 3 mm in over 0.3 s, then held for 1 s.
  constexpr int n = 7;  // the largest node count: x
  constexpr double kDepth = 0.003;
  SendEveryMillisecond(client, 1500, [&](std::int64_t seq) {
    const double z = seq <= 200 ? -0.003 : kDepth * std::min(1.0, (seq - 200) / 300.0);
    return std::array<double, 3>{0.03, 0.02, z};
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  const std::vector<DeformationListener::Received> frames = listener.Frames();
  const std::vector<force_feedback_t> forces = client.Forces();
  daemon.Signal(SIGTERM);
  EXPECT_EQ(daemon.Wait(5), 0) << daemon.Log();
  std::filesystem::remove_all(std::filesystem::path(control).parent_path());
  ASSERT_GT(frames.size(), 50u) << daemon.Log();

  // 7 × 5 × 4 nodes, 5 × 3 × 2 of them inside: 110 on the surface, each id decoding into the box.
  const deformation_t& first = frames.front().message;
  EXPECT_EQ(first.nodes_per_axis, n);
  EXPECT_DOUBLE_EQ(first.spacing_m, 0.01);
  ASSERT_EQ(first.num_ids, 7 * 5 * 4 - 5 * 3 * 2);
  for (int32_t id : first.node_ids) {
    const int x = id / (n * n), y = id / n % n, z = id % n;
    ASSERT_TRUE(x <= 6 && y <= 4 && z <= 3) << id;
    EXPECT_TRUE(x == 0 || x == 6 || y == 0 || y == 4 || z == 0 || z == 3) << id;
  }
  const int32_t touched_id = (3 * n + 2) * n + 0, held_id = (3 * n + 2) * n + 3;
  const deformation_t& last = frames.back().message;
  EXPECT_EQ(last.contact_node[0], 3);
  EXPECT_EQ(last.contact_node[1], 2);
  EXPECT_EQ(last.contact_node[2], 0);
  const auto touched = NodeDisplacement(last, first.node_ids, touched_id);
  const auto held = NodeDisplacement(last, first.node_ids, held_id);
  ASSERT_TRUE(touched && held);
  EXPECT_NEAR((*touched)[2], kDepth, 1e-4);
  for (int c = 0; c < 3; ++c) EXPECT_EQ((*held)[c], 0.0f) << c;

  // The force over the last 100 ms of the hold against the static solution at 3 mm.
  const SceneModel model(LoadSceneFile(scene_path));
  const std::vector<double> driven{0.0, 0.0, kDepth};
  const StaticSolution solved = SolveStatic(model.model(), driven, 1e-12);
  ASSERT_TRUE(solved.converged);
  ASSERT_GT(forces.size(), 200u);
  // (The answers after the last input hold it until it is stale, then release the force: left out.)
  double mean_z = 0;
  int answers = 0;
  for (const force_feedback_t& f : forces) {
    if (f.seq <= 1400 || (f.flags & force_feedback_t::FLAG_INPUT_STALE)) continue;
    EXPECT_TRUE(f.flags & force_feedback_t::FLAG_IN_CONTACT) << f.seq;
    mean_z += f.force[2];
    ++answers;
  }
  ASSERT_GT(answers, 90);
  mean_z /= answers;
  std::printf("block: %zu frames, touched node at %.5f m; force %.5f N, static %.5f N\n",
              frames.size(), (*touched)[2], mean_z, -solved.driven_reaction[2]);
  ASSERT_GT(solved.driven_reaction[2], 0.01);  // pressed in (+z), the hand is pushed back (−z)
  EXPECT_NEAR(mean_z, -solved.driven_reaction[2], 0.02 * solved.driven_reaction[2]);
}

}  // namespace
}  // namespace hapticsim
