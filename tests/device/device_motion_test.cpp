// The simulated device's inputs: reproducible, and doing what each kind promises.
#include "device/device_motion.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "core/error.hpp"

namespace hapticsim::device {
namespace {

TEST(DeviceMotion, ThePressGoesFromAboveTheSurfaceToItsDepthAndBack) {
  MotionSettings s;  // 1 cm at 1 Hz, from 2 mm above the middle of the front face
  DeviceMotion press(s);
  std::vector<std::array<double, 3>> tips;
  for (int n = 0; n <= 1000; ++n) tips.push_back(press.Next());
  EXPECT_DOUBLE_EQ(tips[0][2], -0.002);
  EXPECT_NEAR(tips[500][2], 0.01, 1e-12);
  EXPECT_NEAR(tips[1000][2], -0.002, 1e-12);
  EXPECT_DOUBLE_EQ(tips[300][0], 0.125);
  EXPECT_DOUBLE_EQ(tips[300][1], 0.125);
}

TEST(DeviceMotion, TheWalkIsReproducibleAndTouchesDownSomewhereNewEachTime) {
  MotionSettings s;
  s.kind = "walk";
  s.seed = 11;
  DeviceMotion a(s), b(s);
  s.seed = 12;
  DeviceMotion other(s);
  std::set<std::pair<long, long>> touch_points;
  std::array<double, 3> previous = a.Next();
  (void)b.Next();
  (void)other.Next();
  double fastest = 0;
  bool differs = false;
  for (int n = 1; n < 20000; ++n) {
    const auto tip = a.Next();
    ASSERT_EQ(tip, b.Next()) << "same seed, different walk at period " << n;
    differs = differs || tip != other.Next();
    if (previous[2] <= 0 && tip[2] > 0) {
      touch_points.insert({std::lround(tip[0] * 1000), std::lround(tip[1] * 1000)});  // mm
    }
    for (int c = 0; c < 2; ++c) {
      ASSERT_GE(tip[c], 0.1 * s.edge_m - 1e-12);
      ASSERT_LE(tip[c], 0.9 * s.edge_m + 1e-12);
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

}  // namespace
}  // namespace hapticsim::device
