#include "daemon/thread_health.hpp"

#include <algorithm>
#include <cstdio>

#include "daemon/haptic_loop.hpp"

namespace hapticsim {

std::vector<ThreadBeat> HealthBeats(HapticLoop& loop, double primary_period_s,
                                    std::int64_t io_alive_ns, std::int64_t regions_since_ns,
                                    bool regions_asleep, std::int64_t choice_since_ns,
                                    std::int64_t verify_since_ns) {
  std::vector<ThreadBeat> beats;
  beats.push_back({"primary (hsim-primary)", loop.primary_alive_ns(),
                   std::max(0.1, 50 * primary_period_s), true, true});
  beats.push_back({"I/O (hsim-io)", io_alive_ns, 0.5, true, true});
  const AsyncRegions& regions = loop.regions();
  for (int r = 1; r < regions.num_regions(); ++r) {
    beats.push_back({regions.partition().RegionName(r) + " (hsim-region" + std::to_string(r) + ")",
                     std::max(loop.monitor(r).last_done_ns(), regions_since_ns), 0.5,
                     !regions_asleep, false});
  }
  constexpr double kLongestJob_s = 300;
  beats.push_back({"hsim-choose", choice_since_ns, kLongestJob_s, choice_since_ns != 0, false});
  beats.push_back({"hsim-verify", verify_since_ns, kLongestJob_s, verify_since_ns != 0, false});
  return beats;
}

std::vector<Stall> StalledThreads(const std::vector<ThreadBeat>& beats, std::int64_t now_ns) {
  std::vector<Stall> stalls;
  for (const ThreadBeat& beat : beats) {
    if (!beat.expected) continue;
    const double silent_s = static_cast<double>(now_ns - beat.last_ns) * 1e-9;
    if (silent_s > beat.max_silence_s) stalls.push_back({beat.name, silent_s, beat.force_path});
  }
  return stalls;
}

std::string DescribeStalls(const std::vector<Stall>& stalls) {
  std::string text;
  for (const Stall& stall : stalls) {
    char seconds[32];
    std::snprintf(seconds, sizeof seconds, " (%.1f s)", stall.silent_s);
    text += (text.empty() ? "" : ", ") + stall.name + seconds;
  }
  return text;
}

bool AnyOnForcePath(const std::vector<Stall>& stalls) {
  return std::any_of(stalls.begin(), stalls.end(), [](const Stall& s) { return s.force_path; });
}

std::optional<std::string> StallReport::Due(const std::vector<Stall>& stalls, std::int64_t now_ns) {
  std::string names;
  for (const Stall& stall : stalls) names += stall.name + ";";
  if (names == said_names_ && (names.empty() || now_ns - said_ns_ <= kRepeat_ns)) {
    return std::nullopt;
  }
  said_names_ = names;
  said_ns_ = now_ns;
  return DescribeStalls(stalls);
}

}  // namespace hapticsim
