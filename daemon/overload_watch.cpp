#include "daemon/overload_watch.hpp"

#include <fmt/format.h>

#include <cstddef>

namespace hapticsim {

void OverloadWatch::Count(int region, std::int64_t misses) {
  if (region >= static_cast<int>(misses_.size())) misses_.resize(region + 1, 0);
  misses_[region] += misses;
}

void OverloadWatch::Reset(std::int64_t now_ns) {
  window_end_ns_ = now_ns + 1'000'000'000;
  misses_.clear();
  over_.clear();
}

int OverloadWatch::Check(std::int64_t now_ns, const std::vector<double>& rates_hz) {
  if (window_end_ns_ == 0) Reset(now_ns);
  if (now_ns < window_end_ns_) return -1;
  window_end_ns_ += 1'000'000'000;
  if (window_end_ns_ <= now_ns) window_end_ns_ = now_ns + 1'000'000'000;  // a stalled supervisor
  misses_.resize(rates_hz.size(), 0);
  over_.resize(rates_hz.size(), 0);
  int overloaded = -1;
  for (std::size_t r = 0; r < rates_hz.size(); ++r) {
    over_[r] = static_cast<double>(misses_[r]) > share_ * rates_hz[r] ? over_[r] + 1 : 0;
    if (over_[r] >= windows_ && overloaded < 0) {
      overloaded = static_cast<int>(r);
      last_misses_ = misses_[r];
    }
    misses_[r] = 0;
  }
  if (overloaded >= 0) over_.assign(over_.size(), 0);
  return overloaded;
}

std::string ChoosingCheaperLine(const std::string& region, std::int64_t misses, double rate_hz,
                                double cost_us_per_ms) {
  return fmt::format(
      "{} thread missed {} of its {} periods in the last second, and more than 5 % in each of "
      "the 3 before: choosing a configuration cheaper than {} µs per simulated ms (deadlines "
      "before accuracy)",
      region, misses, rate_hz, cost_us_per_ms);
}

std::string CannotChooseCheaperLine(const std::string& region, std::int64_t misses,
                                    const char* why) {
  return fmt::format(
      "{} thread keeps missing deadlines ({} in the last second) and the supervisor cannot "
      "choose a cheaper configuration ({}): give it a CPU of its own (realtime.cpus, "
      "realtime.fifo_priority) or pin a cheaper one",
      region, misses, why);
}

}  // namespace hapticsim
