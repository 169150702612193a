#pragma once

#include <array>
#include <cstdint>
#include <optional>

#include "core/scene/scene.hpp"
#include "daemon/contact_object.hpp"

namespace hapticsim {

/**
 * Where the tool tip touches the object and how far it has pressed: the primary thread's contact
 * state, as plain logic (no threads, no allocation) so it can be tested on its own.
 *
 * The object is its voxels in the object frame (ContactObject: the paper's cube, or a geometry's
 * voxels, which may leave some of its lattice empty). The tip is in contact while it is strictly
 * inside one. At touch-down the entry face is the face of the object's surface the tip is least
 * deep behind along an axis (ContactObject::EntryOf); the entry point
 * is the tip projected on that face, and the contact node is the surface node nearest to the
 * entry point (never one a support holds: a free neighbour instead, ContactObject::NearestDrivable;
 * on a held face none, and the touch renders nothing until the tip has left the object).
 * While in contact the node follows the tip: displacement = tip − entry point, in all three
 * directions. The node stays the same until lift-off (as in the paper, the contact does not slide).
 *
 * The regions are centred on one node. A touch-down on another node waits (zero force, "waiting"
 * set) until the regions are centred on it, then engages with its force ramped in from zero: the
 * displacement is tip − entry point scaled by a smoothstep from 0 to 1 over `engage_ramp_s`, so
 * neither the node's position nor its velocity jumps however deep the tip went while waiting.
 *
 * After a restart from rest (a reset or a fault) a tip already inside renders nothing until it has
 * left the object once: engaging it at once would step the contact from rest to its depth.
 *
 * Every other way into contact that would step the node ramps too, over the same smoothstep:
 * a touch-down found deeper than kDeepTouchDown_m (a session that begins inside the object, or a
 * tip that jumped in) ramps from zero, fresh input after a stale gap (Hold) ramps from the
 * held displacement to the tip's, and a tip that jumped while engaged (late input) is caught up
 * with over kCatchUp_ns from the node's own path. That own path never leaves the object: its
 * part outwards along the entry face's normal is cut (a tool that only pushes cannot pull the
 * node out, whatever velocity a mispredicted tip gave it); where it meets the face, its normal
 * velocity stops, the one velocity change a ramp makes at once.
 */
class ContactTracker {
 public:
  ContactTracker(const ContactObject& object, double engage_ramp_s);

  /** The result of one update. */
  struct Contact {
    bool engaged = false;  ///< the contact node is driven: render its reaction
    bool waiting = false;  ///< the tip is inside, on a node the regions are not centred on
    std::array<double, 3> displacement_m{};  ///< of the contact node (zero unless engaged)
    std::array<double, 3> inward_normal{};   ///< the entry face's, into the object (0: none)
    std::array<double, 3> point_m{};  ///< where the driven node is: entry point + displacement
    /// A sliding contact's (SlidingContact): the regions should follow the proxy onto the wanted
    /// node, the object's motion carried, at once.
    bool following = false;
  };

  /**
   * One period with a fresh tip position. `centre`: the node the regions are centred on, or none
   * while the regions are being replaced (nothing engages then).
   */
  Contact Update(const std::array<double, 3>& tip_m, std::int64_t now_ns,
                 const std::optional<LatticeIndex>& centre) noexcept;
  /** One period without fresh input: the contact holds where it was. */
  Contact Hold(std::int64_t now_ns, const std::optional<LatticeIndex>& centre) noexcept;

  /** The regions restart from rest: any contact is released and must lift off first. */
  void RestartFromRest() noexcept;
  /** The regions restart from rest around a new centre: an engaged or waiting contact engages
   * again with its force ramped in from zero. */
  void RestartKeepingContact() noexcept;
  /**
   * New regions took over with the old ones' motion, the contact node where the last regions
   * held it (`held_m`, at `held_at_ns`) while the tip went on: an engaged contact goes on from
   * there at the velocity it had and catches up with the tip over kCatchUp_ns, or what is left
   * of a ramp under way if longer (a smoothstep, as after a jump), so neither the node's position
   * nor its velocity steps.
   */
  void CatchUpFrom(const std::array<double, 3>& held_m, std::int64_t held_at_ns) noexcept;

  /**
   * The node the regions should be centred on: the touched node while inside, else the surface
   * node nearest to the tip (so the regions can be moved there before it lands). None before the
   * first input.
   */
  std::optional<LatticeIndex> wanted_node() const { return wanted_; }

  /** True while the tip is outside the object (or before the first input). */
  bool outside() const { return state_ == State::kFree; }

  /** A touch-down deeper than this ramps in from zero, m (a tip at 1 kHz moves far less). */
  static constexpr double kDeepTouchDown_m = 0.5e-3;
  /**
   * A tip whose step differs from its last step by more than this jumped (input late by more
   * than the resampler continues over, then caught up): the node catches up over kCatchUp_ns.
   * On a loaded machine jumps of 34 and 48 µm were measured, each a 0.1–0.2 N spike on a 1.4 N
   * press (the contact node's stiffness over one period is about 4 kN/m). A hand changes its
   * per-period motion by far less: a 1 cm, 1 Hz press by 0.2 µm, a hand accelerating at 10 m/s²
   * by 10 µm. Above this, a fast hand is caught up with too: smoothed, never stepped.
   */
  static constexpr double kCatchUpJump_m = 10e-6;
  static constexpr std::int64_t kCatchUp_ns = 20'000'000;
  /**
   * A tip that leaves the object sideways while still pressed into it along the entry face's
   * normal — over a step of a curved object's voxel staircase, past its rim — lets the node go
   * back to rest over this, by the same smoothstep from its own path, its force rendered and
   * flagged in contact meanwhile. Let go in one period, the organ's node pressed 4.9 mm (0.56 N)
   * sprang back at once: the port guard's slew ceiling stepped the hand by 0.5 N, and the
   * released organ rang with 1.5 mJ more than it held before (docs/operations.md).
   */
  static constexpr std::int64_t kSlipOff_ns = 20'000'000;

  /** The surface node a touch at a point on (or projected onto) the surface drives; never a held
   *  one, and none on a held face (ContactObject::NearestDrivable). */
  std::optional<LatticeIndex> NearestContactNode(
      const std::array<double, 3>& surface_point_m) const noexcept;

 private:
  enum class State { kFree, kAwaitLiftOff, kWaiting, kEngaged };
  Contact Advance(std::int64_t now_ns, const std::optional<LatticeIndex>& centre) noexcept;
  bool TipJumped(const std::array<double, 3>& tip_m) const noexcept;
  // Outside the object: true while an engaged contact slips off (kSlipOff_ns), starting it if
  // the tip left sideways while still pressed in (or through the far side of a part thinner
  // than the press: the test is the depth past the entry face's plane).
  bool SlipsOff(const std::array<double, 3>& tip_m, std::int64_t now_ns, bool after_gap) noexcept;
  // A slip under way goes on (after an input gap, from where the node was held): true until the
  // node is back at rest.
  bool GoesOnSlipping(std::int64_t now_ns, bool after_gap) noexcept;
  // A tip back inside while its node slips off came in nearest to the node it touched: the
  // contact goes on, instead of a new one. (Back over the rim it went off is such a touch on the
  // cube's 20.8 mm lattice; on finer ones a tip pressed in deeper than half a voxel comes back
  // through the side face nearest the next node: a new touch, once the old node is at rest.)
  bool ReentersThroughOwnNode(const std::array<double, 3>& tip_m) const noexcept;
  // Where the node's own path has taken it by now: on from the last period at its velocity.
  std::array<double, 3> OwnPathNow(std::int64_t now_ns) const noexcept;
  // The ramp's own path `since_s` after it started, its outward part along the entry face's
  // normal removed.
  std::array<double, 3> OwnPathInside(double since_s) const noexcept;
  // The node catches up with the tip from `from_m` at `from_ns`, going on at its velocity, over
  // kCatchUp_ns or what is left of a ramp under way if longer.
  void CatchUp(const std::array<double, 3>& from_m, std::int64_t from_ns) noexcept;
  void StartRamp(const std::array<double, 3>& from_m, const std::array<double, 3>& velocity_m_per_s,
                 std::int64_t duration_ns, std::int64_t now_ns) noexcept;

  ContactObject object_;
  std::int64_t ramp_ns_ = 0;
  State state_ = State::kAwaitLiftOff;
  std::array<double, 3> tip_{};
  std::array<double, 3> entry_{};
  std::array<double, 3> inward_{};
  // A ramp from the node's own path — ramp_from_ going on at ramp_velocity_ (zero and at rest after
  // waiting or a deep touch-down, the held displacement after a stale gap, where the node was
  // going after a jump) — to the tip's displacement, started at ramp_start_ns_.
  bool ramping_ = false;
  std::array<double, 3> ramp_from_{}, ramp_velocity_{};
  std::int64_t ramp_start_ns_ = 0, ramp_duration_ns_ = 0;
  bool held_ = false;                     // the last period was a Hold while engaged
  bool slipping_off_ = false;             // engaged, the tip outside: the node goes to rest
  std::array<double, 3> displacement_{};  // the last engaged displacement
  std::array<double, 3> velocity_{};      // of the displacement over the last period, m/s
  std::int64_t last_ns_ = 0;              // when displacement_ was set
  // The tip's last fresh position and its step before that: a jump is a step unlike the last.
  // Counted while inside without a gap (0, 1, 2: enough for a step to compare with).
  std::array<double, 3> last_tip_{}, tip_step_{};
  int fresh_tips_ = 0;
  LatticeIndex node_{};
  std::optional<LatticeIndex> wanted_;
};

}  // namespace hapticsim
