#include "tools/hapticsim/deformation_watch.hpp"

#include <algorithm>
#include <cmath>
#include <ctime>

#include "core/error.hpp"

namespace hapticsim::cli {
namespace {

std::int64_t MonotonicUs() {
  timespec now{};
  clock_gettime(CLOCK_MONOTONIC, &now);
  return static_cast<std::int64_t>(now.tv_sec) * 1'000'000 + now.tv_nsec / 1000;
}

double Quantile(std::vector<double> values, double q) {
  if (values.empty()) return 0;
  const size_t k = std::min(values.size() - 1, static_cast<size_t>(q * values.size()));
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
  return values[k];
}

}  // namespace

DeformationWatch::DeformationWatch(const std::string& lcm_url, const std::string& channel)
    : lcm_(lcm_url) {
  HAPTICSIM_THROW_UNLESS(lcm_.good(), "LCM could not start on " + lcm_url);
  lcm_.subscribe(channel, &DeformationWatch::On, this)->setQueueCapacity(200);
  thread_ = std::thread([this] {
    while (!stop_) lcm_.handleTimeout(20);
  });
}

DeformationWatch::~DeformationWatch() { Stop(); }

void DeformationWatch::Stop() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
}

void DeformationWatch::On(const lcm::ReceiveBuffer*, const std::string&,
                          const deformation_t* frame) {
  const double way_ms = (MonotonicUs() - frame->utime) * 1e-3;
  bool finite = true;
  for (const auto& row : frame->displacement_m) {
    for (float v : row) finite = finite && std::isfinite(v);
  }
  std::lock_guard lock(mutex_);
  ++frames_;
  if (last_frame_ >= 0 && frame->frame > last_frame_ + 1) lost_ += frame->frame - last_frame_ - 1;
  last_frame_ = frame->frame;
  if (!finite) ++nonfinite_;
  latency_ms_.push_back(frame->latency_ms + way_ms);
}

std::int64_t DeformationWatch::frames() const {
  std::lock_guard lock(mutex_);
  return frames_;
}

nlohmann::json DeformationWatch::Summary() const {
  std::lock_guard lock(mutex_);
  return {
      {"deformation_frames", frames_},
      {"deformation_frames_lost", lost_},
      {"deformation_nonfinite", nonfinite_},
      {"deformation_latency_ms",
       {{"median", Quantile(latency_ms_, 0.5)},
        {"p99", Quantile(latency_ms_, 0.99)},
        {"max",
         latency_ms_.empty() ? 0.0 : *std::max_element(latency_ms_.begin(), latency_ms_.end())}}}};
}

}  // namespace hapticsim::cli
