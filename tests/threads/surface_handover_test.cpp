// The deformed surface taken while hapticsimd's loop runs (HapticLoop::TakeSurface, the
// deformation thread's call): on real threads, while the supervisor replaces the regions and
// while they go to sleep and wake, every frame taken is whole and finite, and the seqlocked
// array under it never hands a reader a torn copy. Run under ThreadSanitizer too (scripts/test.sh).
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <thread>
#include <vector>

#include "daemon/haptic_loop.hpp"
#include "daemon/supervisor.hpp"
#include "ipc/shm_segment.hpp"
#include "rt/seqlock_array.hpp"
#include "tests/support/play_device.hpp"
#include "tests/support/sanitized.hpp"

namespace hapticsim {
namespace {

TEST(SeqlockArray, ReadersNeverSeeATornCopy) {
  SeqlockArray array(512);
  std::atomic<bool> stop{false};
  std::thread writer([&] {
    // As a region publishes: a write, then a while before the next (a writer that never pauses
    // starves every seqlock reader, by design).
    for (std::uint64_t k = 1; !stop; ++k) {
      array.Write([k](std::size_t i) { return k + 0.0 * i; });
      std::this_thread::sleep_for(std::chrono::microseconds(20));
    }
  });
  while (array.writes() == 0) std::this_thread::yield();
  std::vector<double> copy(array.size());
  int consistent = 0, raced = 0;
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(2);
  while ((consistent < 2000 || array.writes() < 1000) && std::chrono::steady_clock::now() < end) {
    if (!array.TryRead(copy.data())) {
      ++raced;
      continue;
    }
    for (double v : copy) ASSERT_EQ(v, copy[0]) << "a torn copy was handed out";
    ++consistent;
  }
  stop = true;
  writer.join();
  EXPECT_GT(consistent, 100) << "the reader hardly ever got a copy";
  EXPECT_GT(array.writes(), 100u) << "the writer hardly raced the reader";
  std::printf("seqlock array: %d whole copies, %d reads raced by a write\n", consistent, raced);
}

// The shared-memory surface (ShmDeformationArea) between two mappings of one segment: a reader
// racing the writer's two alternating frames gets whole frames only (every value of frame k is k).
TEST(ShmDeformationArea, AReaderGetsWholeFramesWhileTheWriterAlternates) {
  constexpr std::uint32_t kNodes = 500;
  shm::MappedSegment daemon = shm::MappedSegment::CreateSealed("hapticsim-test", kNodes);
  shm::MappedSegment driver = shm::MappedSegment::Adopt(dup(daemon.fd()), "the test");
  std::atomic<bool> stop{false};
  std::atomic<std::int64_t> written{0};
  std::thread writer([&] {
    std::vector<std::int32_t> ids(kNodes);
    std::vector<double> u(3 * kNodes);
    shm::ShmDeformationFrame meta;
    for (std::int64_t k = 0; !stop; ++k) {
      std::fill(ids.begin(), ids.end(), static_cast<std::int32_t>(k));
      std::fill(u.begin(), u.end(), static_cast<double>(k));
      meta.frame = k;
      daemon.deformation().Write(k, meta, ids.data(), u.data());
      written = k + 1;
      std::this_thread::sleep_for(std::chrono::microseconds(50));
    }
  });
  while (written == 0) std::this_thread::yield();
  std::vector<std::int32_t> ids(kNodes);
  std::vector<double> u(3 * kNodes);
  int whole = 0;
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(2);
  while ((whole < 2000 || written < 1000) && std::chrono::steady_clock::now() < end) {
    shm::ShmDeformationFrame meta;
    if (!driver.deformation().Read(&meta, ids.data(), u.data())) continue;
    for (std::int32_t id : ids) ASSERT_EQ(id, meta.frame) << "ids of another frame";
    for (double v : u) ASSERT_EQ(v, static_cast<double>(meta.frame)) << "a torn frame";
    ++whole;
  }
  stop = true;
  writer.join();
  EXPECT_GT(whole, 100);
  EXPECT_GT(written, 100) << "the writer hardly raced the reader";
}

TEST(SurfaceHandover, FramesStayWholeWhileTheRegionsAreReplacedAndSleep) {
  Scene scene;
  scene.adaptivity.primary_size = 3;
  HapticLoop loop(scene, HapticLoop::Options{});
  loop.Start();
  std::atomic<bool> done{false};
  std::atomic<int> frames{0}, refused{0}, asleep_frames{0};
  std::atomic<std::int64_t> last_configuration{-1};
  std::atomic<bool> bad{false};
  // The deformation thread's part, as fast as it can ask.
  std::thread deformation([&] {
    HapticLoop::SurfaceFrame frame;
    while (!done) {
      const bool asleep_before = loop.asleep();
      if (!loop.TakeSurface(20'000'000, &frame)) {
        ++refused;
        continue;
      }
      const bool whole = frame.displacement_m.size() == 3 * frame.ids.size() && !frame.ids.empty();
      bool finite = true;
      for (double u : frame.displacement_m) finite = finite && std::isfinite(u);
      if (!whole || !finite || frame.configuration_id < last_configuration) bad = true;
      last_configuration = frame.configuration_id;
      ++frames;
      if (asleep_before && loop.asleep()) ++asleep_frames;  // asleep all through the taking
    }
  });
  // The supervisor's part: four replacements, on two nodes and two configurations.
  std::thread supervisor([&] {
    for (int k = 0; k < 4; ++k) {
      std::this_thread::sleep_for(std::chrono::milliseconds(150));
      const bool odd = k % 2 == 1;
      loop.Reconfigure(SceneWith(scene, RegionConfiguration{odd ? 3 : 2, 2, 600},
                                 odd ? LatticeIndex{6, 6, 0} : LatticeIndex{3, 9, 0}));
    }
  });
  // A tool that touches 1 mm deep, leaves for 1.5 s (the regions come to rest and sleep: the
  // material's damping takes 1 mm to 0.1 µm in about 0.9 s) and touches again.
  testing::PlayDevice(loop, 2200, [](int period) {
    const bool touching = period < 300 || period >= 1800;
    return std::array<double, 3>{0.125, 0.125, touching ? 0.001 : -0.01};
  });
  supervisor.join();
  const std::int64_t sleeps = loop.sleeps();
  done = true;
  deformation.join();
  loop.Stop();
  EXPECT_FALSE(bad) << "a frame was not whole, not finite, or went back a configuration";
  EXPECT_GT(frames, 20);
  EXPECT_GE(last_configuration, 4) << "frames of the last regions were never taken";
  // (Under a sanitizer the steps are too slow to keep up, and whether the regions reach rest in
  // time is not what is checked there.)
  if (!kSanitized) {
    EXPECT_GE(sleeps, 1) << "the regions never slept: the frames taken while asleep were not "
                            "tested";
    EXPECT_GT(asleep_frames, 0) << "no frame was taken while the regions slept";
  }
  std::printf(
      "surface frames: %d taken (%d while asleep), %d asked again after a replacement; %lld "
      "sleeps\n",
      frames.load(), asleep_frames.load(), refused.load(), static_cast<long long>(sleeps));
}

}  // namespace
}  // namespace hapticsim
