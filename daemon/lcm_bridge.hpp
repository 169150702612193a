#pragma once

#include <ctime>
#include <deque>
#include <lcm/lcm-cpp.hpp>
#include <mutex>
#include <optional>

#include "daemon/daemon_config.hpp"
#include "daemon/haptic_loop.hpp"
#include "daemon/input_counters.hpp"
#include "daemon/input_intake.hpp"
#include "hapticsim/command_t.hpp"
#include "hapticsim/status_t.hpp"

namespace hapticsim {

/**
 * The LCM side of the I/O thread: decodes device inputs and commands itself (so a malformed
 * message or one with the wrong fingerprint is counted, not just printed by LCM), checks inputs
 * through its InputIntake, publishes forces and the status
 * the supervisor posts. Poll/Publish are called from the I/O thread only; PostStatus and
 * PopCommand from the supervisor.
 */
class LcmBridge {
 public:
  /** @throws Error when LCM cannot be set up on the URL (the message says what to check). */
  LcmBridge(const DaemonConfig& config, HapticLoop& loop, InputCounters& counters);

  /** Handles the messages that arrive within `timeout`. */
  void Poll(const timespec& timeout);
  void Publish(const ForceRecord& record);
  void PublishPendingStatus();

  void PostStatus(const status_t& status);
  std::optional<command_t> PopCommand();

 private:
  void OnDevice(const lcm::ReceiveBuffer* buffer, const std::string& channel);
  void OnCommand(const lcm::ReceiveBuffer* buffer, const std::string& channel);

  const DaemonConfig& config_;
  InputCounters& counters_;
  lcm::LCM lcm_;
  InputIntake intake_;
  std::mutex mutex_;  // guards the two queues below (never touched by real-time threads)
  std::optional<status_t> status_;
  std::deque<command_t> commands_;
};

}  // namespace hapticsim
