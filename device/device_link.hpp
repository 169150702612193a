#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "device/execution_history.hpp"
#include "hapticsim/status_t.hpp"

namespace hapticsim::device {

/** One force as the device received it. */
struct Answer {
  std::int64_t period = -1;          ///< the daemon's primary period (a gap: a lost answer)
  std::int64_t seq = -1;             ///< the newest input it answers
  std::int64_t daemon_utime_us = 0;  ///< when the daemon computed it
  std::int64_t received_ns = 0;      ///< CLOCK_MONOTONIC at the device
  std::array<double, 3> force_n{};
  double error_percent = -1;
  std::int32_t flags = 0;
  std::int64_t first_seq = -1;  ///< the oldest input it answers (all from first_seq to seq)
};

/** How the simulated device reaches hapticsimd: LCM or shared memory. */
class DeviceLink {
 public:
  virtual ~DeviceLink() = default;
  /** One device input. */
  virtual void Send(std::int64_t seq, std::int64_t utime_us,
                    const std::array<double, 3>& position_m) = 0;
  /** Messages that are no device input (bad-input tests): bytes of no type and a message of
   * another type. False where unsupported. */
  virtual bool SendGarbage() { return false; }
  /** Appends the answers received since the last call, oldest first. Never blocks. */
  virtual void Collect(std::vector<Answer>* out) = 0;
  /** True when answers are only seen by calling Collect often (shared memory). */
  virtual bool needs_polling() const = 0;
  /** The daemon's newest status, where the link carries it (LCM). */
  virtual std::optional<status_t> LastStatus() const { return std::nullopt; }
  /** The daemon threads' compute time per period over every status received so far (LCM). */
  virtual std::vector<RegionExecution> Execution() const { return {}; }
  virtual std::string name() const = 0;
};

/**
 * LCM: publishes device_input_t on `device_channel` (unless listen_only), receives
 * force_feedback_t and status_t on a thread of its own.
 * @throws Error when LCM cannot start on the URL.
 */
std::unique_ptr<DeviceLink> MakeLcmLink(const std::string& url, const std::string& device_channel,
                                        const std::string& force_channel,
                                        const std::string& status_channel,
                                        bool listen_only = false);

/**
 * Shared memory through ShmDeviceClient, from the daemon serving `socket_path`. @throws Error when
 * no daemon serves it, it is not to be trusted, or it refuses this driver.
 */
std::unique_ptr<DeviceLink> MakeShmLink(const std::string& socket_path);

/** hapticsimd's default LCM URL: multicast that never leaves the host (ttl=0). */
inline constexpr const char* kHostLocalLcmUrl = "udpm://239.255.76.67:7667?ttl=0";

}  // namespace hapticsim::device
