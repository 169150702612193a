#include "tools/hapticsim/deformation_watch.hpp"

#include <cmath>
#include <ctime>

#include "core/error.hpp"
#include "device/device_session.hpp"
#include "ipc/lcm_start.hpp"

namespace hapticsim::cli {
namespace {

std::int64_t MonotonicUs() {
  timespec now{};
  clock_gettime(CLOCK_MONOTONIC, &now);
  return static_cast<std::int64_t>(now.tv_sec) * 1'000'000 + now.tv_nsec / 1000;
}

}  // namespace

DeformationWatch::DeformationWatch(const std::string& lcm_url, const std::string& channel)
    : lcm_(lcm_url) {
  const std::string problem = LcmStartProblem(lcm_, lcm_url);
  HAPTICSIM_THROW_UNLESS(problem.empty(), problem);
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
  latency_us_.push_back((frame->latency_ms + way_ms) * 1e3);
}

std::int64_t DeformationWatch::frames() const {
  std::lock_guard lock(mutex_);
  return frames_;
}

nlohmann::json DeformationWatch::Summary() const {
  std::lock_guard lock(mutex_);
  std::vector<double> latency_us = latency_us_;
  const device::LatencySummary latency = device::Summarise(latency_us);
  return {{"deformation_frames", frames_},
          {"deformation_frames_lost", lost_},
          {"deformation_nonfinite", nonfinite_},
          {"deformation_latency_ms",
           {{"median", latency.median_us * 1e-3},
            {"p99", latency.p99_us * 1e-3},
            {"max", latency.max_us * 1e-3}}}};
}

}  // namespace hapticsim::cli
