// The simulated device's inputs: reproducible, and doing what each kind promises.
#include "device/device_motion.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <lcm/lcm-cpp.hpp>
#include <limits>
#include <optional>
#include <set>
#include <vector>

#include "core/error.hpp"
#include "hapticsim/device_input_t.hpp"

namespace hapticsim::device {
namespace {

TEST(DeviceMotion, ThePressGoesFromAboveTheSurfaceToItsDepthAndBack) {
  MotionSettings s;  // 1 cm at 1 Hz, from 2 mm above the middle of the front face
  DeviceMotion press(s);
  std::vector<std::array<double, 3>> tips;
  for (int n = 0; n <= 1000; ++n) tips.push_back(press.Next().value());
  EXPECT_DOUBLE_EQ(tips[0][2], -0.002);
  EXPECT_NEAR(tips[500][2], 0.01, 1e-12);
  EXPECT_NEAR(tips[1000][2], -0.002, 1e-12);
  EXPECT_DOUBLE_EQ(tips[300][0], 0.125);
  EXPECT_DOUBLE_EQ(tips[300][1], 0.125);
}

// A block, not the cube (hapticsim device --scene): the walk stays on its front face per axis, and
// a press point or a depth outside it is refused naming the block's extent.
// A stroke (a sliding tool's palpation): in from above, along +x at depth, out, and back above the
// surface, each leg smooth; a stroke that would leave the face is refused, naming --length.
TEST(DeviceMotion, AStrokeGoesInAlongTheFaceOutAndBackAndOneOffTheFaceIsRefused) {
  MotionSettings s;
  s.kind = "stroke";
  s.amplitude_m = 0.005;
  s.stroke_length_m = 0.06;
  s.at_m = {0.09, 0.125};
  DeviceMotion stroke(s);  // 1 Hz: a stroke per 1000 periods
  std::vector<std::array<double, 3>> tips;
  for (int n = 0; n <= 1000; ++n) tips.push_back(stroke.Next().value());
  EXPECT_DOUBLE_EQ(tips[0][2], -0.002);
  EXPECT_NEAR(tips[200][2], 0.005, 1e-12);  // in
  EXPECT_NEAR(tips[200][0], 0.09, 1e-12);
  EXPECT_NEAR(tips[700][0], 0.15, 1e-12);  // along, at depth
  EXPECT_NEAR(tips[450][2], 0.005, 1e-12);
  EXPECT_NEAR(tips[800][2], -0.002, 1e-12);  // out
  EXPECT_NEAR(tips[1000][0], 0.09, 1e-12);   // back above the start
  double fastest = 0;
  for (std::size_t n = 1; n < tips.size(); ++n) {
    fastest =
        std::max(fastest, std::hypot(tips[n][0] - tips[n - 1][0], tips[n][2] - tips[n - 1][2]));
  }
  // The fastest leg is the way back above the surface, 60 mm in 0.2 s; a smoothstep tops 1.5 × its
  // mean speed: nothing jumps.
  EXPECT_LT(fastest, 0.06 / 200 * 1.5 + 1e-9);
  for (double y : {tips[300][1], tips[900][1]}) EXPECT_DOUBLE_EQ(y, 0.125);
  s.stroke_length_m = 0.2;
  try {
    DeviceMotion off(s);
    FAIL() << "a stroke off the face was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("--length"), std::string::npos) << e.what();
  }
}

TEST(DeviceMotion, OnABlockTheWalkStaysOnItsFaceAndAPressOffItIsRefused) {
  MotionSettings s;
  s.kind = "walk";
  s.extent_m = {0.08, 0.04, 0.03};  // the palpation phantom
  s.at_m = {0.04, 0.02};
  s.amplitude_m = 0.003;
  DeviceMotion walk(s);
  for (int n = 0; n < 20000; ++n) {
    const std::array<double, 3> tip = walk.Next().value();
    for (int c = 0; c < 2; ++c) {
      ASSERT_GE(tip[c], 0.1 * s.extent_m[c] - 1e-12) << "axis " << c << " period " << n;
      ASSERT_LE(tip[c], 0.9 * s.extent_m[c] + 1e-12) << "axis " << c << " period " << n;
    }
  }
  s.kind = "press";
  s.at_m = {0.06, 0.05};  // y past the block's 40 mm
  try {
    DeviceMotion refused(s);
    FAIL() << "a press off the block's face was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("0 ≤ y ≤ 0.04"), std::string::npos) << e.what();
  }
  s.at_m = {0.04, 0.02};
  s.amplitude_m = 0.03;  // as deep as the block
  EXPECT_THROW(DeviceMotion deep(s), Error);
}

// An object whose front is at two depths: 10 × 6 columns of 1 cm, the four left columns' front
// at z = 2 cm (a step cut out), the rest at z = 0, and one column empty through (a hole at x 8–9
// cm, y 2–3 cm). Each motion starts from the front over its own point; a point over the hole is
// refused naming --at; the walk's waypoints stay over the object at their own depths (its legs may
// cross the hole).
TEST(DeviceMotion, OverAnObjectWithEmptyVoxelsEachMotionStartsFromTheFrontUnderIt) {
  MotionSettings s;
  s.extent_m = {0.10, 0.06, 0.04};
  s.front.spacing_m = 0.01;
  s.front.columns = {10, 6};
  for (int y = 0; y < 6; ++y) {
    for (int x = 0; x < 10; ++x) s.front.z_m.push_back(x < 4 ? 0.02 : 0.0);
  }
  s.front.z_m[8 + 10 * 2] = std::numeric_limits<double>::quiet_NaN();
  s.amplitude_m = 0.003;
  s.hover_m = 0.002;
  s.kind = "press";
  s.at_m = {0.025, 0.03};  // over the step
  DeviceMotion step(s);
  std::array<double, 3> tip = step.Next().value();
  EXPECT_NEAR(tip[2], 0.018, 1e-12);  // 2 mm above the step's floor
  for (int n = 1; n <= 500; ++n) tip = step.Next().value();
  EXPECT_NEAR(tip[2], 0.023, 1e-9);  // 3 mm into it, half a period on
  s.at_m = {0.065, 0.03};            // over the front face right of the step
  EXPECT_NEAR(DeviceMotion(s).Next().value()[2], -0.002, 1e-12);
  s.kind = "stroke";
  s.at_m = {0.005, 0.025};
  s.stroke_length_m = 0.03;
  tip = DeviceMotion(s).Next().value();
  EXPECT_NEAR(tip[2], 0.018, 1e-12);
  s.kind = "press";
  s.at_m = {0.025, 0.03};
  s.amplitude_m = 0.025;  // from the step's floor at 2 cm, past the back at 4 cm
  try {
    DeviceMotion refused(s);
    FAIL() << "a press past the back was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("past its lattice's back"), std::string::npos) << e.what();
  }
  s.amplitude_m = 0.003;
  s.at_m = {0.085, 0.025};  // over the hole
  try {
    DeviceMotion refused(s);
    FAIL() << "a press over no voxel was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("--at 0.085,0.025"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("no voxel under"), std::string::npos) << e.what();
  }
  s.kind = "walk";
  s.at_m = {0.05, 0.03};
  DeviceMotion walk(s);
  int on_step = 0, deep_on_step = 0, over_hole = 0;
  for (int n = 0; n < 60000; ++n) {
    tip = walk.Next().value();
    const std::optional<double> front = s.front.At(tip[0], tip[1]);
    if (!front) {  // a leg between two waypoints over the object may cross the hole
      ++over_hole;
      continue;
    }
    if (*front > 0.01) {
      ++on_step;
      deep_on_step += tip[2] > 0.02 ? 1 : 0;
    }
  }
  EXPECT_LT(over_hole, 60000 / 50) << "waypoints over the hole";
  EXPECT_GT(on_step, 1000);
  EXPECT_GT(deep_on_step, 100) << "the walk never pressed into the step's floor";
}

TEST(DeviceMotion, TheWalkIsReproducibleAndTouchesDownSomewhereNewEachTime) {
  MotionSettings s;
  s.kind = "walk";
  s.seed = 11;
  DeviceMotion a(s), b(s);
  s.seed = 12;
  DeviceMotion other(s);
  std::set<std::pair<long, long>> touch_points;
  std::array<double, 3> previous = a.Next().value();
  (void)b.Next();
  (void)other.Next();
  double fastest = 0;
  bool differs = false;
  for (int n = 1; n < 20000; ++n) {
    const std::array<double, 3> tip = a.Next().value();
    ASSERT_EQ(tip, b.Next().value()) << "same seed, different walk at period " << n;
    differs = differs || tip != other.Next();
    if (previous[2] <= 0 && tip[2] > 0) {
      touch_points.insert({std::lround(tip[0] * 1000), std::lround(tip[1] * 1000)});  // mm
    }
    for (int c = 0; c < 2; ++c) {
      ASSERT_GE(tip[c], 0.1 * s.extent_m[c] - 1e-12);
      ASSERT_LE(tip[c], 0.9 * s.extent_m[c] + 1e-12);
    }
    ASSERT_LE(tip[2], s.amplitude_m + 1e-12);
    fastest = std::max(
        fastest,
        std::hypot(tip[0] - previous[0], tip[1] - previous[1], tip[2] - previous[2]) * 1000);
    previous = tip;
  }
  EXPECT_TRUE(differs);
  EXPECT_GE(touch_points.size(), 5u) << "touch-downs at distinct points in 20 s";
  EXPECT_LE(fastest, s.walk_speed_m_per_s * 1.01);  // smoothstep legs: top speed as set
  EXPECT_GT(fastest, s.walk_speed_m_per_s * 0.5);
}

TEST(DeviceMotion, BadSettingsAreRefusedNamingTheOption) {
  MotionSettings s;
  s.kind = "jump";
  EXPECT_THROW(DeviceMotion{s}, Error);
  s.kind = "press";
  s.at_m = {0.3, 0.1};
  try {
    DeviceMotion motion(s);
    ADD_FAILURE() << "a point off the face was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("--at"), std::string::npos) << e.what();
  }
}

// A recorded session that went silent for 0.1 s (a driver that stalled, or the bad-input test's
// stale gap) replays that silence instead of running on: the replay once kept only the inputs,
// in order, and the pause vanished. Timed by the device's own utime, not the logger's clock.
TEST(DeviceMotion, AReplayKeepsTheRecordedSilences) {
  const std::string path = ::testing::TempDir() + "hapticsim_replay_silence.lcmlog";
  {
    lcm::LogFile log(path, "w");
    ASSERT_TRUE(log.good());
    auto write = [&](std::int64_t seq, std::int64_t utime_us, double z) {
      device_input_t input{};
      input.utime = utime_us;
      input.seq = seq;
      input.position[0] = input.position[1] = 0.125;
      input.position[2] = z;
      std::vector<std::uint8_t> bytes(static_cast<std::size_t>(input.getEncodedSize()));
      input.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
      lcm::LogEvent event{};
      event.timestamp = 5'000'000;  // the logger received them all at once: no timing here
      event.channel = "HAPTIC_DEVICE";
      event.datalen = static_cast<std::int32_t>(bytes.size());
      event.data = bytes.data();
      log.writeEvent(&event);
    };
    write(1, 1'000'000, 0.001);
    write(2, 1'001'000, 0.002);
    write(3, 1'002'000, 0.003);
    write(4, 1'103'000, 0.004);  // 101 ms later: 100 silent periods
    write(5, 1'104'400, 0.005);  // 1.4 periods: jitter, not a silence
  }
  MotionSettings s;
  s.kind = "replay";
  s.replay_path = path;
  DeviceMotion replay(s);
  EXPECT_EQ(replay.replay_periods(), 3 + 100 + 2);
  std::vector<std::optional<std::array<double, 3>>> periods;
  for (int n = 0; n < 110; ++n) periods.push_back(replay.Next());
  for (int n = 0; n < 3; ++n) EXPECT_NEAR(periods[n].value()[2], 0.001 * (n + 1), 1e-15);
  for (int n = 3; n < 103; ++n) EXPECT_FALSE(periods[n].has_value()) << "period " << n;
  EXPECT_NEAR(periods[103].value()[2], 0.004, 1e-15);
  EXPECT_NEAR(periods[104].value()[2], 0.005, 1e-15);
  EXPECT_NEAR(periods[109].value()[2], 0.005, 1e-15);  // then the last input, held
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace hapticsim::device
