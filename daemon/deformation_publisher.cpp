#include "daemon/deformation_publisher.hpp"

#include <pthread.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "daemon/lcm_bridge.hpp"
#include "daemon/shm_server.hpp"
#include "rt/background_priority.hpp"

namespace hapticsim {

DeformationPublisher::DeformationPublisher(const DaemonConfig& config, HapticLoop& loop,
                                           LcmBridge* bridge, ShmServer* shm)
    : config_(config), loop_(loop), bridge_(bridge), shm_(shm) {
  // Nowhere to send frames: the regions are not asked for any.
  if (bridge_ || shm_) thread_ = std::thread([this] { Run(); });
}

DeformationPublisher::~DeformationPublisher() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
}

deformation_t DeformationPublisher::Message(const HapticLoop::SurfaceFrame& frame,
                                            std::int64_t number, bool with_ids) {
  deformation_t out{};
  out.frame = number;
  out.configuration_id = static_cast<std::int32_t>(frame.configuration_id);
  out.primary_size = frame.configuration.primary_size;
  out.secondary_lod = frame.configuration.secondary_lod;
  out.secondary_rate_hz = frame.configuration.secondary_rate_hz;
  for (int c = 0; c < 3; ++c) out.contact_node[c] = frame.centre[c];
  out.in_contact = frame.in_contact;
  out.complete = frame.complete;
  out.nodes_per_axis = frame.nodes_per_axis;
  out.spacing_m = frame.spacing_m;
  if (with_ids) out.node_ids = frame.ids;
  out.num_ids = static_cast<std::int32_t>(out.node_ids.size());
  out.num_nodes = static_cast<std::int32_t>(frame.ids.size());
  out.displacement_m.resize(frame.ids.size());
  for (size_t i = 0; i < frame.ids.size(); ++i) {
    const double* u = &frame.displacement_m[3 * i];
    out.displacement_m[i] = {static_cast<float>(u[0]), static_cast<float>(u[1]),
                             static_cast<float>(u[2])};
  }
  return out;
}

void DeformationPublisher::Run() {
  pthread_setname_np(pthread_self(), "hsim-deform");
  // Its frames are for the eye: where two cores are short, the region threads go first.
  if (!BackOffFromRealTimeThreads())
    spdlog::warn("deformation thread: could not lower its priority");
  const auto period_ns = static_cast<std::int64_t>(std::llround(1e9 / config_.deformation_rate_hz));
  HapticLoop::SurfaceFrame frame;
  std::int64_t next_ns = HapticLoop::NowNs(), ids_sent_ns = 0, number = 0;
  std::int64_t ids_configuration = -1;
  while (!stop_.load()) {
    const std::int64_t now = HapticLoop::NowNs();
    if (now < next_ns) {
      std::this_thread::sleep_for(
          std::chrono::nanoseconds(std::min<std::int64_t>(next_ns - now, 20'000'000)));
      continue;
    }
    // The next frame on the grid, not a burst to catch up after a late one.
    next_ns += period_ns * std::max<std::int64_t>(1, (now - next_ns) / period_ns + 1);
    // A region that has not stepped within this long is stalled: its last part is sent.
    const std::int64_t max_wait_ns = std::min<std::int64_t>(period_ns, 50'000'000);
    if (!loop_.TakeSurface(max_wait_ns, &frame)) continue;  // regions replaced: the next frame
    const bool with_ids = frame.configuration_id != ids_configuration ||
                          HapticLoop::NowNs() - ids_sent_ns >= kIdsEvery_s * 1e9;
    deformation_t message = Message(frame, number, with_ids);
    const std::int64_t sent_ns = HapticLoop::NowNs();
    message.utime = sent_ns / 1000;
    message.latency_ms = static_cast<float>((sent_ns - frame.asked_ns) * 1e-6);
    if (bridge_) bridge_->PublishDeformation(message);
    if (shm_) shm_->OfferDeformation(frame, message.utime, number);
    if (with_ids) {
      ids_configuration = frame.configuration_id;
      ids_sent_ns = sent_ns;
    }
    ++number;
    frames_.store(number, std::memory_order_relaxed);
    max_latency_ms_.store(std::max(max_latency_ms_.load(std::memory_order_relaxed),
                                   static_cast<double>(message.latency_ms)),
                          std::memory_order_relaxed);
  }
}

}  // namespace hapticsim
