// The deformed surface's contact flag (HapticLoop::TakeSurface, the deformation thread's frame)
// against the periods the test plays through hapticsimd's real primary period: it says what the
// newest period answered, however long ago that was. A primary woken late beside a busy neighbour
// (no real-time privileges) has not let the tool go; a tool lifted off is out at once.
#include <gtest/gtest.h>

#include <chrono>
#include <optional>
#include <thread>

#include "daemon/haptic_loop.hpp"
#include "tests/support/play_device.hpp"

namespace hapticsim {
namespace {

// Periods played on this thread on the real clock, the tool at depth `z` (m) at the front face's
// middle; returns whether the last one answered in contact.
bool PlayPeriods(HapticLoop& loop, int periods, double z, std::int64_t* seq) {
  bool in_contact = false;
  for (int n = 0; n < periods; ++n, ++*seq) {
    const std::int64_t now = HapticLoop::NowNs();
    testing::PlayPeriodInVirtualTime(loop, now, DeviceSample{*seq, now, {0.125, 0.125, z}, false});
    ForceRecord record;
    while (loop.forces().Pop(&record)) in_contact = record.flags & force_flags::kInContact;
  }
  return in_contact;
}

bool FrameSaysInContact(HapticLoop& loop) {
  HapticLoop::SurfaceFrame frame;
  EXPECT_TRUE(loop.TakeSurface(0, &frame));
  return frame.in_contact;
}

TEST(SurfaceContact, AFrameTakenWhileThePrimaryIsLateSaysTheToolIsStillInContact) {
  Scene scene;
  scene.adaptivity.primary_size = 3;
  scene.adaptivity.secondary_rate_hz = 1000;
  HapticLoop loop(scene, HapticLoop::Options{});
  std::int64_t seq = 0;
  ASSERT_FALSE(PlayPeriods(loop, 20, -0.002, &seq));
  EXPECT_FALSE(FrameSaysInContact(loop));
  ASSERT_TRUE(PlayPeriods(loop, 100, 0.001, &seq)) << "the tool 1 mm in never touched";
  EXPECT_TRUE(FrameSaysInContact(loop));
  // The primary does not run for 20 periods: late, not lifted off.
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_TRUE(FrameSaysInContact(loop)) << "a late primary was taken for a lift-off";
  // Lifted off: out once the periods say so (the five periods' bridge over a reconfiguration's
  // pause passes too).
  ASSERT_FALSE(PlayPeriods(loop, 5, -0.002, &seq)) << "the tool lifted 2 mm out still touches";
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_FALSE(FrameSaysInContact(loop)) << "out of contact, still flagged in contact";
}

}  // namespace
}  // namespace hapticsim
