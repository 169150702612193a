#include "daemon/input_resampler.hpp"

#include <algorithm>

namespace hapticsim {

InputResampler::InputResampler(double device_period_s, double max_ahead_s) noexcept
    : period_ns_(device_period_s * 1e9), max_ahead_ns_(max_ahead_s * 1e9) {}

void InputResampler::Add(std::int64_t seq, std::int64_t received_ns,
                         const std::array<double, 3>& position_m) noexcept {
  // The timeline counts device periods from its first input, so that device times stay small
  // enough for a double to hold every one exactly (s · T near 2⁶² lost whole seconds, and two
  // inputs shared one time). An input that does not continue it starts a new one: a seq that
  // goes back (a restarted driver), a leap past the history (inputs lost by the hundred, or a seq
  // no device counts to), or a timeline too long for its times to be exact.
  std::int64_t gap = 0;
  const bool continues = count_ > 0 && !__builtin_sub_overflow(seq, newest_seq_, &gap) && gap > 0 &&
                         gap <= kHistory &&
                         static_cast<double>(newest_periods_ + gap) * period_ns_ <= kExactNs;
  if (!continues) Reset();
  newest_periods_ = continues ? newest_periods_ + gap : 0;
  const double device_ns = static_cast<double>(newest_periods_) * period_ns_;
  const double latency_ns = static_cast<double>(received_ns) - device_ns;
  if (count_ > 0 && latency_ns > latency_floor_ns_ + kRelock_ns) Reset();
  latencies_ns_[next_latency_] = latency_ns;
  next_latency_ = (next_latency_ + 1) % kLatencyWindow;
  latencies_ = std::min(latencies_ + 1, kLatencyWindow);
  latency_floor_ns_ = LatencyFloor();
  newest_ = (newest_ + 1) % kHistory;
  history_[newest_] = {device_ns, position_m};
  newest_seq_ = seq;
  count_ = std::min(count_ + 1, kHistory);
}

double InputResampler::LatencyFloor() const noexcept {
  // The ring in order, oldest first; the latencies are one seq apart only if no input was lost,
  // which is close enough for a trend (a lost input makes the trend look a little steeper).
  auto at = [this](int i) {
    return latencies_ns_[(next_latency_ - latencies_ + i + kLatencyWindow) % kLatencyWindow];
  };
  // How much later each seq arrives than the one before, from the quickest of each half.
  double trend_ns = 0;
  const int half = latencies_ / 2;
  if (half >= 2) {
    double older = at(0), newer = at(half);
    for (int i = 1; i < half; ++i) older = std::min(older, at(i));
    for (int i = half + 1; i < 2 * half; ++i) newer = std::min(newer, at(i));
    trend_ns = std::max(0.0, (newer - older) / half);
  }
  double floor_ns = at(latencies_ - 1);
  for (int i = 0; i < latencies_; ++i) {
    floor_ns = std::min(floor_ns, at(i) + trend_ns * (latencies_ - 1 - i));
  }
  return floor_ns;
}

std::array<double, 3> InputResampler::TipAt(std::int64_t at_ns) const noexcept {
  if (count_ == 0) return {};
  if (count_ == 1) return Newest(0).position_m;
  // On the device's timeline, one device period back; never before the oldest input held, never
  // further past the newest than the prediction may go. Between the two inputs around it (past
  // the newest: on the line through the newest two).
  const double t = std::clamp(static_cast<double>(at_ns) - latency_floor_ns_ - period_ns_,
                              Newest(count_ - 1).device_ns, Newest(0).device_ns + max_ahead_ns_);
  int i = 0;  // t lies between Newest(i + 1) and Newest(i), or past the newest
  while (i + 2 < count_ && Newest(i + 1).device_ns > t) ++i;
  const Input& a = Newest(i + 1);
  const Input& b = Newest(i);
  if (!(b.device_ns > a.device_ns)) return b.position_m;  // never 0 / 0
  const double u = (t - a.device_ns) / (b.device_ns - a.device_ns);
  std::array<double, 3> tip{};
  for (int c = 0; c < 3; ++c) tip[c] = a.position_m[c] + u * (b.position_m[c] - a.position_m[c]);
  return tip;
}

}  // namespace hapticsim
