#pragma once

#include <atomic>
#include <cstdint>
#include <thread>

#include "daemon/daemon_config.hpp"
#include "daemon/haptic_loop.hpp"
#include "hapticsim/deformation_t.hpp"

namespace hapticsim {

class LcmBridge;
class ShmServer;

/**
 * The deformation thread: at [deformation] rate_hz it takes the deformed surface from the loop
 * (HapticLoop::TakeSurface), publishes it as deformation_t on lcm.deformation_channel and offers it
 * to the shared-memory session (ShmServer::OfferDeformation; the I/O thread writes it). It runs
 * at normal priority, off the real-time path: the region threads only copy their part of the
 * surface when asked. A frame late by more than a period is not made up: the next is taken on the
 * next free tick of its grid.
 */
class DeformationPublisher {
 public:
  /** Node ids are sent in the first frame of each configuration and at least this often. */
  static constexpr double kIdsEvery_s = 1.0;

  /** `bridge`, `shm`: where frames go (either may be null; both null, no thread starts). Starts
   *  the thread. */
  DeformationPublisher(const DaemonConfig& config, HapticLoop& loop, LcmBridge* bridge,
                       ShmServer* shm);
  ~DeformationPublisher();
  DeformationPublisher(const DeformationPublisher&) = delete;
  DeformationPublisher& operator=(const DeformationPublisher&) = delete;

  /** Frames sent since start, and the largest time from asking the regions to sending, ms. */
  std::int64_t frames() const { return frames_.load(std::memory_order_relaxed); }
  double max_latency_ms() const { return max_latency_ms_.load(std::memory_order_relaxed); }

  /** The message of one frame: ids only when `with_ids`. */
  static deformation_t Message(const HapticLoop::SurfaceFrame& frame, std::int64_t number,
                               bool with_ids);

 private:
  void Run();

  const DaemonConfig& config_;
  HapticLoop& loop_;
  LcmBridge* bridge_;
  ShmServer* shm_;
  std::atomic<bool> stop_{false};
  std::atomic<std::int64_t> frames_{0};
  std::atomic<double> max_latency_ms_{0};
  std::thread thread_;
};

}  // namespace hapticsim
