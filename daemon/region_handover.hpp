#pragma once
// The handshake by which hapticsimd's supervisor takes the regions from the primary thread to
// replace them, and gives them back (HapticLoop::Reconfigure).

#include <atomic>
#include <cstdint>

namespace hapticsim {

/** What the primary does to the contact when new regions resume (Reconfigure's hand-over). */
enum class RegionRestart : int {
  kNone = 0,            ///< nothing (applied already)
  kFromRest = 1,        ///< a tool inside must lift off before it feels force again
  kKeepingContact = 2,  ///< a tool inside engages again, its force ramped in from zero
  kCarryingMotion = 3,  ///< the contact carries on from where the last period held it
};

/**
 * The supervisor ↔ primary handshake of a reconfiguration. The primary thread owns the regions
 * except between its acknowledgement of a pause and the release the supervisor resumes it at:
 *
 *   supervisor: RequestPause(hold) ……… Acknowledged()? ……… (replaces the regions) … Resume(r, t)
 *   primary:          each period: Period(release) → kPaused (the first one acknowledges) …
 *                                   … kWaiting until release t … kOurs, and TakeRestart() is r
 *
 * Memory order:
 * - The request is a release store that the primary's acquire load pairs with: it carries the
 *   hold flag written before it.
 * - The acknowledgement is a release store, repeated every paused period, that Acknowledged()
 *   acquires: everything the primary wrote to the regions before it is visible to the supervisor,
 *   and the primary does not touch them after it.
 * - Resume() stores the restart (relaxed), the resume release (release) and withdraws the request
 *   (release); the primary's acquire of the withdrawn request makes both visible, and with them
 *   everything the supervisor wrote to the new regions.
 * Nothing here blocks or allocates; the supervisor's wait for the acknowledgement is its own.
 */
class RegionHandover {
 public:
  /** What a primary period may do with the regions. */
  enum class Period {
    kOurs,     ///< step them
    kPaused,   ///< do not touch them: the supervisor may be replacing them
    kWaiting,  ///< new regions, not started yet: their first release is later
  };

  /** Before the primary thread starts: it owns the regions from `resume_at_ns` on. */
  void Reset(RegionRestart restart, std::int64_t resume_at_ns) noexcept {
    requested_.store(false);
    acknowledged_.store(false);
    restart_.store(static_cast<int>(restart));
    resume_at_ns_.store(resume_at_ns);
  }
  /** While the primary thread is stopped: what it does to the contact when it next starts. */
  void SetRestartWhileStopped(RegionRestart restart) noexcept {
    restart_.store(static_cast<int>(restart));
  }

  /** Supervisor: asks the primary to leave the regions alone; `hold_force`: see hold_force(). */
  void RequestPause(bool hold_force) noexcept {
    hold_force_.store(hold_force, std::memory_order_relaxed);  // published by the request
    acknowledged_.store(false, std::memory_order_relaxed);
    requested_.store(true, std::memory_order_release);
  }
  /** Supervisor: the primary has paused; the regions are the supervisor's until Resume(). */
  bool Acknowledged() const noexcept { return acknowledged_.load(std::memory_order_acquire); }
  /** Supervisor: gives up a pause not acknowledged (the old regions carry on). */
  void Withdraw() noexcept { requested_.store(false, std::memory_order_release); }
  /** Supervisor, after replacing the regions: the primary runs them from `resume_at_ns` on. */
  void Resume(RegionRestart restart, std::int64_t resume_at_ns) noexcept {
    restart_.store(static_cast<int>(restart), std::memory_order_relaxed);
    resume_at_ns_.store(resume_at_ns, std::memory_order_release);
    requested_.store(false, std::memory_order_release);
  }
  /** Supervisor: the last restart, if the primary has not applied it yet (else kNone). */
  RegionRestart unapplied_restart() const noexcept {
    return static_cast<RegionRestart>(restart_.load(std::memory_order_acquire));
  }

  /**
   * Primary, each period released at `release_ns`: whether it may step the regions. The first
   * paused period of a pause sets *pause_began (else it is left false).
   */
  Period Check(std::int64_t release_ns, bool* pause_began) noexcept {
    *pause_began = false;
    if (requested_.load(std::memory_order_acquire)) {
      *pause_began = !acknowledged_.load(std::memory_order_relaxed);
      acknowledged_.store(true, std::memory_order_release);
      return Period::kPaused;
    }
    return release_ns >= resume_at_ns_.load(std::memory_order_acquire) ? Period::kOurs
                                                                      : Period::kWaiting;
  }
  /** Primary: a pause is asked for (an idle primary must not wait for input). */
  bool pause_requested() const noexcept { return requested_.load(std::memory_order_acquire); }
  /** Primary, in a pause: the supervisor carries the motion, so an engaged force may be held. */
  bool hold_force() const noexcept { return hold_force_.load(std::memory_order_relaxed); }
  /** Primary, the first period the regions are its own: the restart to apply, once. */
  RegionRestart TakeRestart() noexcept {
    return static_cast<RegionRestart>(
        restart_.exchange(static_cast<int>(RegionRestart::kNone), std::memory_order_acq_rel));
  }

 private:
  std::atomic<bool> requested_{false}, acknowledged_{false}, hold_force_{false};
  std::atomic<int> restart_{static_cast<int>(RegionRestart::kNone)};
  std::atomic<std::int64_t> resume_at_ns_{0};
};

}  // namespace hapticsim
