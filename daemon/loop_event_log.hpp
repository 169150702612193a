#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "daemon/black_box.hpp"
#include "daemon/daemon_config.hpp"
#include "daemon/haptic_loop.hpp"
#include "daemon/miss_logger.hpp"
#include "daemon/overrun_burst.hpp"

namespace hapticsim {

/**
 * What the haptic loop did since the supervisor's last tick, said in the log: secondary regions
 * that stalled, a primary boundary gone stale, deadline misses (a line per burst and thread), the
 * black box of the last primary periods when the primary overruns again and again or a force
 * fault latches, and faults re-armed. Reads the loop's counters and rings only; what follows
 * from them (a cheaper configuration, a restart from rest) is the caller's. Supervisor thread.
 */
class LoopEventLog {
 public:
  /** `config`: the running one (its log.max_lines_per_s may change on SIGHUP). */
  LoopEventLog(HapticLoop& loop, const DaemonConfig& config);

  /** Missed periods per region, as drained from their deadline monitors. */
  using Misses = std::array<std::int64_t, HapticLoop::kMaxRegions>;
  /** The loop's stalls, boundary age and deadline misses since the last call, said. */
  Misses ReadDeadlines(std::int64_t now_ns);
  /** Whether a force fault latched since the last call (said, with the black box at most once
   *  every 10 s); a re-armed fault is said too. */
  bool ReadFaults(std::int64_t now_ns);
  /** Says every miss not yet said (at a stop). */
  void Flush(std::int64_t now_ns);

  static constexpr size_t kBlackBoxCycles = 100;  // primary periods (0.1 s at 1 kHz)
  /** Steps that held a late Γ are said per this window, where at least this share of steps. */
  static constexpr std::int64_t kHeldBoundaryWindow_ns = 10'000'000'000;
  static constexpr double kHeldBoundaryShare = 0.01;

 private:
  void MatchMissLoggers(std::int64_t now_ns);
  void ReadStalls();
  void ReadBoundaryAge();
  void ReadHeldBoundaries(std::int64_t now_ns);

  HapticLoop& loop_;
  const DaemonConfig& config_;
  BlackBox black_box_{kBlackBoxCycles};
  OverrunBurst overrun_;
  std::vector<MissLogger> miss_loggers_;  // one per region thread
  // Per region, as last logged.
  std::array<std::int64_t, HapticLoop::kMaxRegions> stalls_seen_{}, skipped_seen_{};
  bool boundary_stale_ = false;  // the secondary region has not run for kStaleBoundary_s
  // Per inner region: its steps that held their outer Γ (AsyncRegions::held_boundary_steps) as
  // last read from the regions of `held_reconfigurations_`, and those not said yet since
  // `held_since_ns_`.
  std::array<std::int64_t, HapticLoop::kMaxRegions> held_seen_{}, held_unsaid_{};
  std::int64_t held_reconfigurations_ = 0, held_since_ns_ = 0;
  std::int64_t faults_seen_ = 0, rearms_seen_ = 0;
  std::int64_t last_fault_dump_ns_ = -1;  // none yet (CLOCK_MONOTONIC starts at boot)
};

}  // namespace hapticsim
