#pragma once

#include <atomic>
#include <cstdint>
#include <lcm/lcm-cpp.hpp>
#include <mutex>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

#include "hapticsim/deformation_t.hpp"

namespace hapticsim::cli {

/**
 * What a viewer of a running hapticsimd receives on its deformation channel, as the soak reports
 * it: frames, frames lost on the way (gaps in deformation_t::frame), non-finite displacements,
 * and the latency from the daemon asking its regions to the frame arriving here (the daemon's
 * own latency_ms plus the way, both on this host's CLOCK_MONOTONIC).
 */
class DeformationWatch {
 public:
  DeformationWatch(const std::string& lcm_url, const std::string& channel);
  ~DeformationWatch();
  DeformationWatch(const DeformationWatch&) = delete;
  DeformationWatch& operator=(const DeformationWatch&) = delete;

  /** Stops listening; Summary then holds still. */
  void Stop();
  /** deformation_frames, deformation_frames_lost, deformation_nonfinite and
   *  deformation_latency_ms {median, p99, max}. */
  nlohmann::json Summary() const;
  std::int64_t frames() const;

 private:
  void On(const lcm::ReceiveBuffer*, const std::string&, const deformation_t* frame);

  lcm::LCM lcm_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
  mutable std::mutex mutex_;
  std::int64_t frames_ = 0, lost_ = 0, nonfinite_ = 0, last_frame_ = -1;
  std::vector<double> latency_us_;  // asked to arrived, per frame
};

}  // namespace hapticsim::cli
