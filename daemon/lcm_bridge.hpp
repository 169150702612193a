#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <deque>
#include <lcm/lcm-cpp.hpp>
#include <mutex>
#include <optional>

#include "daemon/daemon_config.hpp"
#include "daemon/haptic_loop.hpp"
#include "daemon/input_guard.hpp"
#include "hapticsim/command_t.hpp"
#include "hapticsim/status_t.hpp"

namespace hapticsim {

/** Counters of the LCM side, read by the supervisor for the status message. */
struct LcmCounters {
  std::atomic<std::int64_t> inputs_received{0}, inputs_rejected{0}, decode_errors{0};
  std::atomic<std::int64_t> forces_published{0}, commands_received{0};
  std::array<std::atomic<std::int64_t>, kNumInputRejections> rejected_by_kind{};
};

/**
 * The I/O thread's LCM side: decodes device inputs and commands itself (so a malformed message or
 * one with the wrong fingerprint is counted, not just printed by LCM), checks inputs with the
 * InputGuard, hands accepted ones to the primary thread, publishes every force the primary
 * thread hands back, and the status the supervisor posts.
 */
class LcmBridge {
 public:
  /** @throws Error when LCM cannot be set up on the URL (the message says what to check). */
  LcmBridge(const DaemonConfig& config, HapticLoop& loop);

  /** The I/O thread's loop, until `stop`. Polls LCM and the force ring every 0.25 ms at most. */
  void Run(const std::atomic<bool>& stop);

  /** Supervisor: the next status to publish. */
  void PostStatus(const status_t& status);
  /** Supervisor: the oldest command received, if any. */
  std::optional<command_t> PopCommand();
  const LcmCounters& counters() const { return counters_; }
  /** Supervisor: the newest rejection not yet logged (kind), and how many since. */
  InputRejection TakeLastRejection();

 private:
  void OnDevice(const lcm::ReceiveBuffer* buffer, const std::string& channel);
  void OnCommand(const lcm::ReceiveBuffer* buffer, const std::string& channel);
  void PublishForces();

  const DaemonConfig& config_;
  HapticLoop& loop_;
  lcm::LCM lcm_;
  InputGuard guard_;
  LcmCounters counters_;
  DeviceSample last_accepted_;
  std::atomic<int> last_rejection_{0};
  std::mutex mutex_;  // guards the two queues below (never touched by real-time threads)
  std::optional<status_t> status_;
  std::deque<command_t> commands_;
};

}  // namespace hapticsim
