// A secondary thread that stalls — stopped from outside by a signal whose handler sleeps, as a
// preemption or a page-fault storm would stop it — while the tool presses into the object: the
// primary keeps answering every period on the held boundary, the stall is seen and counted, and
// the region carries on from the present instead of stepping its missed periods late. Once for
// 0.3 s, and repeatedly (12 ms of every 16 ms for 0.6 s).
#include <dirent.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <ctime>
#include <fstream>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include "daemon/haptic_loop.hpp"
#include "tests/support/sanitized.hpp"

namespace hapticsim {
namespace {

// Under a sanitizer (kSanitized) steps are slower than their periods: forces are not checked.

constexpr long kStallMs = 300;
std::atomic<long> stall_ms{kStallMs};

void SleepInHandler(int) {
  const timespec stall{0, stall_ms.load() * 1'000'000};
  nanosleep(&stall, nullptr);  // async-signal-safe
}

// The kernel thread id of this process's thread named `name` (-1: none).
pid_t ThreadNamed(const std::string& name) {
  DIR* tasks = opendir("/proc/self/task");
  if (!tasks) return -1;
  pid_t found = -1;
  while (dirent* entry = readdir(tasks)) {
    if (entry->d_name[0] == '.') continue;
    std::ifstream comm(std::string("/proc/self/task/") + entry->d_name + "/comm");
    std::string comm_name;
    std::getline(comm, comm_name);
    if (comm_name == name) found = static_cast<pid_t>(std::stol(entry->d_name));
  }
  closedir(tasks);
  return found;
}

struct StallRun {
  std::vector<ForceRecord> forces;
  double largest_jump_n = 0, final_force_n = 0, oldest_boundary_s = 0;
  std::int64_t stalls = 0, skipped = 0;
  int flagged_stale = 0;  // answers flagged kBoundaryStale
};

// Above the front face's middle node for 0.1 s, in at 10 mm/s for 0.3 s, then held for 1.1 s;
// with `stall`, region 1 is stopped for 0.3 s at 0.6 s, while the tool holds the object pressed
// 3 mm in.
enum class Stall { kNone, kOnce, kRepeatedly };

StallRun Press(Stall stall) {
  Scene scene;
  scene.adaptivity.primary_size = 3;
  HapticLoop loop(scene, HapticLoop::Options{});
  struct sigaction action {};
  action.sa_handler = SleepInHandler;
  sigemptyset(&action.sa_mask);
  sigaction(SIGUSR1, &action, nullptr);
  loop.Start();
  StallRun run;
  ForceRecord record;
  auto next = std::chrono::steady_clock::now();
  constexpr double kH = 0.25 / 12;
  for (int n = 0; n < 1500; ++n) {
    const double z = n < 100 ? -0.001 : 1e-5 * std::min(n - 100, 300);
    loop.OfferInput(DeviceSample{n, HapticLoop::NowNs(), {6 * kH, 6 * kH, z}, false});
    // Once: 0.3 s at 0.6 s. Repeatedly: 12 ms of every 16 ms from 0.6 s to 1.2 s, so the region
    // runs a quarter of the time and falls ever further behind.
    const bool once = stall == Stall::kOnce && n == 600;
    const bool repeated = stall == Stall::kRepeatedly && n >= 600 && n < 1200 && n % 16 == 0;
    if (once || repeated) {
      stall_ms = once ? kStallMs : 12;
      const pid_t region1 = ThreadNamed("hsim-region1");
      EXPECT_GT(region1, 0) << "no thread named hsim-region1";
      if (region1 > 0) syscall(SYS_tgkill, getpid(), region1, SIGUSR1);
    }
    run.oldest_boundary_s =
        std::max(run.oldest_boundary_s, loop.regions().primary_boundary_age_s());
    while (loop.forces().Pop(&record)) run.forces.push_back(record);
    next += std::chrono::milliseconds(1);
    std::this_thread::sleep_until(next);
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(5));
  while (loop.forces().Pop(&record)) run.forces.push_back(record);
  loop.Stop();
  run.stalls = loop.stalls(1);
  run.skipped = loop.skipped_periods(1);
  double previous = 0;
  for (const ForceRecord& f : run.forces) {
    if (f.flags & force_flags::kBoundaryStale) ++run.flagged_stale;
    if (!std::isfinite(f.force_n[2])) continue;
    run.largest_jump_n = std::max(run.largest_jump_n, std::abs(f.force_n[2] - previous));
    previous = f.force_n[2];
  }
  run.final_force_n = previous;
  return run;
}

TEST(SecondaryStall, ThePrimaryAnswersOnTheHeldBoundaryAndTheRegionCarriesOnFromThePresent) {
  StallRun calm = Press(Stall::kNone);
  // A calm press that stalled anyway met the machine's hiccup (the secondary woken 3 of its
  // periods late, 5 ms), not the code's: once more. Seen twice in a day: beside a compile, and
  // just after another test run was killed; alone it passed 7 of 7.
  if (calm.stalls > 0 && !kSanitized) calm = Press(Stall::kNone);
  const StallRun stalled = Press(Stall::kOnce);
  const StallRun lagging = Press(Stall::kRepeatedly);
  std::printf("repeated stalls: force step %.4f N, final force %.4f N, %lld stalls, %lld skipped\n",
              lagging.largest_jump_n, lagging.final_force_n, static_cast<long long>(lagging.stalls),
              static_cast<long long>(lagging.skipped));
  std::printf(
      "force step between periods: %.4f N calm, %.4f N with a %ld ms stall; final force %.4f N "
      "calm, %.4f N stalled; boundary up to %.1f ms old; %lld stall(s), %lld periods skipped\n",
      calm.largest_jump_n, stalled.largest_jump_n, kStallMs, calm.final_force_n,
      stalled.final_force_n, stalled.oldest_boundary_s * 1e3,
      static_cast<long long>(stalled.stalls), static_cast<long long>(stalled.skipped));

  for (const StallRun* run : {static_cast<const StallRun*>(&calm), &stalled, &lagging}) {
    for (const ForceRecord& f : run->forces) {
      ASSERT_TRUE(std::isfinite(f.force_n[0] + f.force_n[1] + f.force_n[2]));
    }
  }
  // Under a sanitizer every step is many times slower than its period and signals wait for the
  // sanitizer's safe points: the run checks the threads' hand-over (what the sanitizer is for),
  // not the timing. (Measured under TSan: the primary answered 716 of 1,500 periods and the
  // secondary was more than 3 periods late 68 times without any stall injected.)
  if (kSanitized) return;
  // Seen: the primary's boundary aged through the stall, the region counted it, the answers
  // from 0.1 s into the stall until the region ran again were flagged.
  EXPECT_GT(stalled.oldest_boundary_s, 0.2);
  EXPECT_GE(stalled.stalls, 1);
  EXPECT_GT(stalled.skipped, 0.2 * 600);  // most of 0.3 s at 600 Hz
  EXPECT_GT(stalled.flagged_stale, 150);
  EXPECT_LT(stalled.flagged_stale, 250);
  EXPECT_GE(lagging.stalls, 10);
  // Every period answered: one answer per release across the stall.
  ASSERT_GT(stalled.forces.size(), 1000u);
  const double span = (stalled.forces.back().utime_us - stalled.forces.front().utime_us) / 1000.0;
  EXPECT_NEAR(static_cast<double>(stalled.forces.size()) - 1, span, std::max(2.0, 0.005 * span));
  EXPECT_EQ(calm.stalls, 0);
  EXPECT_EQ(calm.flagged_stale, 0);
  // Bounded through a stall: measured here 0.045 N (as the calm press) in four runs of five and
  // 0.17 N in one, against 0.30 and 0.56 N with the missed periods stepped late (kept in
  // docs/reliability.md; too close to timing to assert more than a safe bound). Afterwards the
  // force of the calm press within the transient the lost 0.3 s leaves (its slowest modes decay as
  // e^(-d t / 2): 5 % after 0.6 s).
  EXPECT_LT(stalled.largest_jump_n, 1.0);
  EXPECT_NEAR(stalled.final_force_n, calm.final_force_n, 0.1 * std::abs(calm.final_force_n));
  // A region stopped three quarters of the time for 0.6 s stays bounded (0.3-0.7 N steps seen).
  EXPECT_LT(lagging.largest_jump_n, 2.0);
  EXPECT_NEAR(lagging.final_force_n, calm.final_force_n, 0.2 * std::abs(calm.final_force_n));
}

}  // namespace
}  // namespace hapticsim
