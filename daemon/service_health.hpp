#pragma once

#include <cstdint>
#include <vector>

#include "daemon/haptic_loop.hpp"
#include "daemon/systemd_notify.hpp"
#include "daemon/thread_health.hpp"

namespace hapticsim {

/**
 * Every thread the force depends on, by its newest sign of life, and what systemd is told of
 * them. A stalled primary or I/O thread (no force computed, or none reaching the device) stops
 * the watchdog pings, so systemd restarts the daemon; a stalled secondary is rendered around (the
 * primary holds its boundary, every answer flagged boundary stale); a background job that never
 * ends is reported. Supervisor thread.
 */
class ServiceHealth {
 public:
  /** Where the background jobs' and the I/O thread's signs of life are read, each tick. */
  struct Signs {
    std::int64_t io_alive_ns = 0;
    std::int64_t choice_since_ns = 0;  ///< the running choice's start, 0: none
    std::int64_t check_since_ns = 0;   ///< the running check's start, 0: none
  };

  ServiceHealth(HapticLoop& loop, const SystemdNotifier& systemd, std::int64_t start_ns);

  /** The threads stalled at `now_ns`. New region threads, or ones just woken, get a moment
   *  before they are expected to have run (read here, just before each check, so a command
   *  that woke the regions earlier in the same tick does not make them look stalled). */
  std::vector<Stall> Stalled(std::int64_t now_ns, const Signs& signs);
  /** Says a change in `stalls` (the log and systemd's status line) and pings the watchdog
   *  while nothing on the force path is stalled. */
  void Report(std::int64_t now_ns, const std::vector<Stall>& stalls);

 private:
  HapticLoop& loop_;
  const SystemdNotifier& systemd_;
  const double primary_period_s_;
  std::int64_t regions_since_ns_;
  std::int64_t reconfigurations_seen_ = 0;
  bool asleep_ = false;
  StallReport stall_report_;  // the stalled threads, as last logged and told to systemd
  std::int64_t next_watchdog_ns_;
};

}  // namespace hapticsim
