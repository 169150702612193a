#pragma once

#include <cstdint>
#include <string>

namespace hapticsim {

/**
 * The systemd notify protocol without libsystemd: datagrams to $NOTIFY_SOCKET ("READY=1",
 * "WATCHDOG=1", "STOPPING=1", "STATUS=…"). Does nothing when the variable is unset (not started by
 * systemd), so the daemon runs the same by hand.
 */
class SystemdNotifier {
 public:
  SystemdNotifier();
  bool enabled() const { return !socket_path_.empty(); }
  /** Sends `state`; false when the socket could not be reached. */
  bool Notify(const std::string& state) const;
  /** $WATCHDOG_USEC as seconds (0 when no watchdog is configured). */
  double watchdog_interval_s() const { return watchdog_s_; }

 private:
  std::string socket_path_;
  double watchdog_s_ = 0;
};

}  // namespace hapticsim
