#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <thread>
#include <vector>

#include "core/async_regions.hpp"
#include "core/seqlock_slot.hpp"
#include "daemon/deadline_monitor.hpp"
#include "daemon/spsc_ring.hpp"

namespace hapticsim {

/** The newest accepted device input, as the I/O thread hands it to the primary thread. */
struct DeviceSample {
  std::int64_t seq = -1;
  std::int64_t received_ns = 0;  ///< CLOCK_MONOTONIC when it arrived
  std::array<double, 3> position_m{};
  bool latest_rejected = false;  ///< the newest message after this one was refused
};

/** One primary period's answer, as the primary thread hands it to the I/O thread. */
struct ForceRecord {
  std::int64_t seq = -1;            ///< the input it answers
  std::int64_t utime_us = 0;        ///< CLOCK_MONOTONIC, µs
  std::array<double, 3> force_n{};  ///< on the user
  double error_percent = -1;
  std::int32_t flags = 0;  ///< force_feedback_t::FLAG_* bits
};

/** One primary period as the black box keeps it (the last cycles are logged on a fault). */
struct BlackBoxRecord {
  std::int64_t time_ns = 0;  ///< the period's wake-up, CLOCK_MONOTONIC
  std::int64_t seq = -1;
  std::array<double, 3> position_m{};
  std::array<double, 3> force_n{};      ///< as sent (zero out of contact or after a fault)
  std::array<double, 3> raw_force_n{};  ///< as simulated
  double error_percent = -1;
  std::int32_t flags = 0;
};

/** Flags of force_feedback_t (kept equal to the LCM constants; a test checks). */
namespace force_flags {
inline constexpr std::int32_t kInContact = 1;
inline constexpr std::int32_t kErrorTargetExceeded = 2;
inline constexpr std::int32_t kLookupClamped = 4;
inline constexpr std::int32_t kInputStale = 8;
inline constexpr std::int32_t kReconfiguring = 16;
inline constexpr std::int32_t kNoErrorMap = 32;
inline constexpr std::int32_t kInputRejected = 64;
}  // namespace force_flags

/**
 * The real-time part of hapticsimd: the asynchronous regions on one thread each. The primary
 * thread runs at the primary rate on absolute CLOCK_MONOTONIC releases; every period it takes the
 * newest device input (a seqlock slot), prescribes the contact, steps, and hands the force to the
 * I/O thread (a lock-free ring). Secondary threads step at their own rates, released ahead as in
 * RealTimeSchedule. None of them allocates, locks, logs or does I/O; deadline misses go to
 * lock-free DeadlineMonitors that the supervisor drains.
 *
 * Contact: the tool tip is in contact while it is inside the object (z > 0 in the object frame).
 * The contact node is the paper's (the front face's middle node); while in contact it follows the
 * tip's depth and its tangential motion since touch-down, so touch-down is continuous. Out of
 * contact the node is held at rest and the force is zero. After a start or restart (a reset, a
 * fault, a reconfiguration) a tip already inside the object renders nothing until it has left
 * the object once.
 */
class HapticLoop {
 public:
  struct Options {
    double stale_after_s = 0.05;
    bool zero_force_when_stale = true;
    double max_force_n = 50;
    int fifo_priority = 0;  ///< SCHED_FIFO for the region threads (0: normal scheduling)
    std::vector<int> cpus;  ///< pin the region threads here (empty: no pinning)
  };
  using ForceRing = SpscRing<ForceRecord, 4096>;
  using BlackBoxRing = SpscRing<BlackBoxRecord, 4096>;

  /** @throws Error for an invalid scene. */
  HapticLoop(const Scene& scene, const Options& options);
  ~HapticLoop();

  /** Starts the region threads. Returns what the system refused of the RT settings ("" = all). */
  std::string Start();
  /** Stops and joins the region threads. */
  void Stop();
  /**
   * Replaces the regions by those of `scene` (another adaptive configuration of the same object),
   * starting from rest: call it only while the tool is out of contact and the object has settled,
   * so nothing the user feels changes. The regions are built before the threads stop, so the
   * loop pauses only for the restart (a few periods, no forces sent). Supervisor thread only.
   * @throws Error for an invalid scene (the running loop is left as it was).
   */
  void Reconfigure(const Scene& scene);
  /** CLOCK_MONOTONIC of the last primary period in contact, ns (0: never). */
  std::int64_t last_contact_ns() const { return last_contact_ns_.load(std::memory_order_relaxed); }
  bool running() const { return running_.load(); }

  /** I/O thread: the newest accepted input. */
  SeqlockSlot<DeviceSample>& input() { return input_; }
  /** I/O thread: the forces, one per primary period. */
  ForceRing& forces() { return forces_; }
  /** Supervisor: every primary period's record, for the black box. */
  BlackBoxRing& black_box() { return black_box_; }
  /** Supervisor: the error and flags every force carries from now on. */
  void SetErrorState(double error_percent, std::int32_t flags) noexcept;
  /** Supervisor: per region. */
  DeadlineMonitor& monitor(RegionIndex region) { return *monitors_[region]; }
  const AsyncRegions& regions() const { return *regions_; }
  /** Primary periods run on stale input, and force faults (non-finite or above max_force_n). */
  std::int64_t stale_periods() const { return stale_periods_.load(std::memory_order_relaxed); }
  std::int64_t force_faults() const { return force_faults_.load(std::memory_order_relaxed); }

  /**
   * One primary period at `now_ns` (what the primary thread runs; public for the allocation test).
   * Never allocates, locks or throws.
   */
  void PrimaryPeriod(std::int64_t now_ns) noexcept;

  static std::int64_t NowNs() noexcept;

 private:
  void PrimaryThread(std::int64_t origin_ns);
  void SecondaryThread(RegionIndex region, std::int64_t origin_ns);
  std::string ApplyRealtimeSettings();
  void BuildSchedule();

  Scene scene_;
  Options options_;
  std::unique_ptr<AsyncRegions> regions_;
  std::vector<std::unique_ptr<DeadlineMonitor>> monitors_;
  SeqlockSlot<DeviceSample> input_;
  ForceRing forces_;
  BlackBoxRing black_box_;
  std::atomic<double> error_percent_{-1};
  std::atomic<std::int32_t> error_flags_{0};
  std::atomic<std::int64_t> stale_periods_{0}, force_faults_{0}, last_contact_ns_{0};
  std::atomic<bool> running_{false}, stop_{false};
  std::vector<std::thread> threads_;
  std::vector<std::int64_t> lead_ns_;
  double tick_ns_ = 0;

  // Primary thread state.
  std::array<double, 3> contact_rest_{};  // the contact node's rest position, object frame
  std::array<double, 3> touch_down_{};
  std::array<double, 3> displacement_{};
  bool in_contact_ = false;
  // After a (re)start the tool must leave the object before it can touch again: engaging a tip
  // that is already deep inside would step the contact from rest to its depth at once.
  bool await_lift_off_ = true;
  DeviceSample last_input_;
};

}  // namespace hapticsim
