#pragma once

#include <ctime>
#include <deque>
#include <lcm/lcm-cpp.hpp>
#include <mutex>
#include <optional>
#include <string>

#include "daemon/daemon_config.hpp"
#include "daemon/haptic_loop.hpp"
#include "daemon/input_counters.hpp"
#include "daemon/input_intake.hpp"
#include "hapticsim/command_t.hpp"
#include "hapticsim/deformation_t.hpp"
#include "hapticsim/status_t.hpp"
#include "ipc/command_signature.hpp"

namespace hapticsim {

/**
 * For a udpm:// URL, the source address this host's multicast to the group carries, when that is
 * not a loopback address: the group is then routed through another interface, so machines on
 * that network can send to the daemon, and a unit whose IP filter admits only localhost
 * (IPAddressAllow=localhost) drops local clients' packets too, which carry that address. Empty
 * when the group is routed through loopback, for other providers, or when it cannot be told.
 * Sends nothing (a connected UDP socket only asks the kernel for the route).
 */
std::string MulticastSourceOffLoopback(const std::string& url);

/**
 * The LCM side of the I/O thread: decodes device inputs and commands itself (so a malformed
 * message or one with the wrong fingerprint is counted, not just printed by LCM), checks inputs
 * through its InputIntake, publishes forces and the status the supervisor posts. Commands pass
 * the signature gate here, as they arrive: one that is refused (unsigned, forged, replayed, or
 * any when commands on LCM are off) is counted and dropped before it can take a place in the
 * queue, so a flood of forgeries cannot crowd out a signed command. Poll/Publish are called from
 * the I/O thread only; PostStatus, PopCommand and CommandRefusals from the supervisor.
 */
class LcmBridge {
 public:
  /**
   * `gate`: the commands to take (lcm.accept_commands); none, every command is refused.
   * @throws Error when LCM cannot be set up on the URL (the message says what to check).
   */
  LcmBridge(const DaemonConfig& config, HapticLoop& loop, InputCounters& counters,
            std::optional<SignedCommandGate> gate);

  /** Handles the messages that arrive within `timeout`. */
  void Poll(const timespec& timeout);
  void Publish(const ForceRecord& record);
  void PublishPendingStatus();
  /** The deformation thread's frames (publishes serialised with the I/O thread's). */
  void PublishDeformation(const deformation_t& frame);

  void PostStatus(const status_t& status);
  std::optional<command_t> PopCommand();

  /** Commands refused so far, and why the newest was. */
  struct Refusals {
    std::int64_t count = 0;
    std::string last_reason;
  };
  Refusals CommandRefusals();

 private:
  // Says at start where LCM traffic goes, and warns where it reaches beyond this host's clients.
  static void LogRoute(const DaemonConfig& config);
  void OnDevice(const lcm::ReceiveBuffer* buffer, const std::string& channel);
  void OnCommand(const lcm::ReceiveBuffer* buffer, const std::string& channel);

  const DaemonConfig& config_;
  InputCounters& counters_;
  lcm::LCM lcm_;
  InputIntake intake_;
  std::optional<SignedCommandGate> gate_;  // the I/O thread's alone
  // Held around every publish: the I/O thread's and the deformation thread's. LCM's udpm and memq
  // providers lock their own sends, its tcpq provider does not (a message is several writes).
  std::mutex publish_mutex_;
  std::mutex mutex_;  // guards what follows (never touched by real-time threads)
  std::optional<status_t> status_;
  std::deque<command_t> commands_;
  Refusals refusals_;
};

}  // namespace hapticsim
