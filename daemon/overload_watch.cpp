#include "daemon/overload_watch.hpp"

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

}  // namespace hapticsim
