#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "core/regions/async_regions.hpp"
#include "core/trial/proxy_contact.hpp"
#include "daemon/contact_object.hpp"
#include "daemon/contact_tracker.hpp"

namespace hapticsim {

/**
 * hapticsimd's tool that slides (contact.model = "proxy"): the primary thread's contact state
 * when the device touches through a proxy (ProxyContact) instead of driving the touched node.
 * The proxy stays on the deformed surface, joined to the tool tip by the contact.stiffness spring;
 * it sticks and slides by Coulomb friction, and the primary region follows it across the face
 * (ProxyWantsPrimaryAt: the supervisor moves the regions with the object's motion carried).
 *
 * Touch-down is through the face the tip is least deep behind, as ContactTracker's, or where that
 * face has no node inside it (a riser of a voxel staircase one voxel high), the next way out that
 * has one, up to a voxel deeper, never the opposite face, none past a held face
 * (ContactObject::WaysOut); the node it wants is the one nearest
 * the entry point inside that face (a rim node's normal is not the face's). The
 * proxy engages wherever the regions it is bound to, on that face, can push under the tip (then
 * they follow it from there); otherwise it waits (zero force, "waiting") until the supervisor has
 * moved them onto the node it wants. Its force ramps in over
 * `engage_ramp_s` (the spring's pull scaled by a smoothstep) wherever it would step: a touch deeper
 * than ContactTracker::kDeepTouchDown_m, after waiting, after regions that restarted from rest, and
 * when the proxy comes back into a primary it slid out of. The spring itself starts from zero at
 * the surface: a touch from outside needs no ramp.
 *
 * A proxy that slides out of the primary (the regions did not follow in time) pushes nothing
 * (zero force, "waiting") and asks for the regions at once; one that slides off the face's rim
 * releases the contact, and the tip must leave the object before it touches again — unless the
 * tool rose out of its face into a wall rising from it (ProxyContact::Result::into_wall_m): then
 * it touches the wall, as from outside, where the wall's way out is at most twice as deep as the
 * tip was past the wall's foot (TouchTheWall). At a wall's foot with the tool past it, below the
 * face, the wall's push is kept whole by the friction cone (a concave corner). Released
 * while it pushes — off the rim, or the tip out of the object sideways still pressed in — its last
 * push fades out first (kReleasing, engaged meanwhile; over kRelease_ns, longer for a large push:
 * kReleaseRate_n_per_ns).
 *
 * Threads: Prepare is any thread's; Bind is the supervisor's, while the primary leaves the
 * regions alone (HapticLoop::Install); everything else is the primary thread's, never allocates,
 * and reads what Bind writes only on regions that are its own (a `centre` given).
 */
class SlidingContact {
 public:
  using Contact = ContactTracker::Contact;

  SlidingContact(const ContactObject& object, const ContactSettings& settings,
                 double engage_ramp_s);

  /** A proxy over new regions' primary, made before they are installed. */
  struct Binding {
    std::optional<ProxyContact> proxy;  ///< none: regions centred on an edge node
    LatticeIndex centre{};
  };
  /**
   * Any thread, before the regions are installed (it allocates): the proxy over `regions`'
   * primary (RegionPartition::PrimaryProxySurface), at their centre.
   * @throws Error when the regions are not a proxy's (RegionPartition::proxy_contact).
   */
  Binding Prepare(const AsyncRegions& regions) const;
  /**
   * The supervisor, while the primary leaves the regions alone (HapticLoop::Install): the proxy
   * bound to the new regions. On the face it was on it goes on where it is, sliding or not (the
   * regions followed it); on another face it starts at their centre, and an engaged contact waits
   * for regions on its own face. Never throws.
   */
  void Bind(Binding binding) noexcept;

  /** One period with the tip at `tip_m` (object frame, m). `centre`: the node the regions are
   *  centred on, or none while they are being replaced (or held: a waiting touch does not engage
   *  then, and nothing Bind writes is read). */
  Contact Update(const std::array<double, 3>& tip_m, std::int64_t now_ns,
                 const std::optional<LatticeIndex>& centre) noexcept;
  /** One period without fresh input: the tool held where it was. */
  Contact Hold(std::int64_t now_ns, const std::optional<LatticeIndex>& centre) noexcept;

  /**
   * One primary period on the bound regions, engaged: the tool moved from the last period's tip
   * to this one's over the primary's substeps, the proxy touched at each and the primary stepped
   * with its push. Returns the push on the object at the period's first substep, N (the user
   * feels its opposite). Out of contact the regions step unloaded.
   */
  std::array<double, 3> StepPeriod(AsyncRegions& regions, std::int64_t now_ns) noexcept;

  /** The node the regions should be centred on: the proxy's node when they should follow it, the
   *  touched node while inside, else the node the tip hovers over. None before the first input. */
  std::optional<LatticeIndex> wanted_node() const { return wanted_; }
  /** True while the tip is outside the object (or before the first input). */
  bool outside() const { return state_ == State::kFree; }
  /** While a push let go fades out (release_ns_): what is left of it at `now_ns`, N; zero
   *  otherwise. What a pause of the regions renders then, instead of the push held. */
  std::array<double, 3> ReleasingPush(std::int64_t now_ns) const noexcept;
  bool releasing() const { return state_ == State::kReleasing; }

  /** The regions restart from rest: any contact is released and must lift off first. */
  void RestartFromRest() noexcept;
  /**
   * New regions took over with the old ones' motion (the regions followed the proxy, or switched
   * configuration in contact) at `now_ns`, after a pause of `paused_ns` in which the user felt the
   * last push held while the tool went on: the push goes from that held one to the spring's own
   * over twice the pause (a smoothstep; at most kCatchUp_ns; the spring pulling from a point that
   * returns to the tool, so that it stays stiff), so the force does not step where the tool moved
   * meanwhile. The proxy follows the tool less what it moved in the pause, given back over the
   * same smoothstep: the tissue takes up where it stood still (a tool lifted off it meanwhile
   * still touches it). `hold_expired`: the pause outlasted the hold and the push was released: it
   * ramps in again from zero instead.
   */
  void CatchUp(std::int64_t now_ns, std::int64_t paused_ns, bool hold_expired) noexcept;
  /** The longest a push blends back after a pause (CatchUp), ns: the node contact's catch-up. */
  static constexpr std::int64_t kCatchUp_ns = ContactTracker::kCatchUp_ns;
  /**
   * A contact let go while it pushes — the tip gone out of the object sideways, still more than
   * ContactTracker::kDeepTouchDown_m past the face's plane (past the rim of the face the proxy
   * lags behind on), or the proxy slid off its face's rim
   * — fades its last push out over this (longer for a large one: kReleaseRate_n_per_ns), by a
   * smoothstep, on the nodes it pushed, rendered and
   * flagged in contact meanwhile; then the tip must leave the object (if it has not) before it
   * touches again. Let go in one period, the push stepped the hand by all of it: 0.13 N off the
   * cube's rim 5 mm in, 0.14 N where a walk over the organ went off a step of its staircase (a
   * push as deep as the tool goes, up to the port guard's 0.5 N a period). The node contact's
   * slip-off time.
   */
  static constexpr std::int64_t kRelease_ns = ContactTracker::kSlipOff_ns;
  /** The fastest a let-go push fades, N/ns (0.08 N per ms): a push over 1.07 N fades over longer
   *  than kRelease_ns, up to kMaxRelease_ns (a push over 2.67 N then fades faster). */
  static constexpr double kReleaseRate_n_per_ns = 0.08e-6;
  /** The longest a let-go push fades: as long as a pause of the regions holds it
   *  (HapticLoop::kMaxHold_s). */
  static constexpr std::int64_t kMaxRelease_ns = 50'000'000;

  /** The regions restart from rest around a new centre: an engaged or waiting contact engages
   *  again under the tip, its force ramped in from zero. */
  void RestartKeepingContact() noexcept;

 private:
  // kReleasing: let go while pushing (the tip out of the object sideways, the proxy off its
  // face's rim), the last push fading out (Release).
  enum class State { kFree, kAwaitLiftOff, kWaiting, kEngaged, kReleasing };
  Contact Answer() const noexcept;
  // The node a sliding touch through `entry` wants: the one nearest it inside its face (its
  // normal the face's, as a proxy needs; never a rim node), none on a held face.
  std::optional<LatticeIndex> NodeInsideFace(const ContactObject::Entry& entry) const noexcept;
  // The same, held or not (a held face: its node, which no touch drives).
  std::optional<LatticeIndex> NearestNodeInsideFace(
      const ContactObject::Entry& entry) const noexcept;
  // `point_m` (the tip, under the face; the proxy) projected onto the touched face's plane.
  ContactObject::Entry OnTouchedFace(const std::array<double, 3>& point_m) const noexcept;
  // A touch of the tip, inside the object: waiting for regions on its face, or engaged at once
  // where the bound ones reach.
  void TouchDown(const std::array<double, 3>& tip_m, std::int64_t now_ns,
                 const std::optional<LatticeIndex>& centre) noexcept;
  // Touches through `entry` (`node`: the one it wants inside that face; none on a held face).
  void TouchThrough(const ContactObject::Entry& entry, const std::optional<LatticeIndex>& node,
                    std::int64_t now_ns, const std::optional<LatticeIndex>& centre) noexcept;
  // Let go into a wall (ProxyContact::Result::into_wall_m), awaiting lift-off: touches it, as
  // TouchDown, where the tip's way out is within wall_within_m_.
  void TouchTheWall(const std::array<double, 3>& tip_m, std::int64_t now_ns,
                    const std::optional<LatticeIndex>& centre) noexcept;
  // Engages a waiting touch when the regions, this period's (`centre`), can push under the tip on
  // its face.
  void TryEngage(const std::optional<LatticeIndex>& centre, std::int64_t now_ns) noexcept;
  double RampScale(std::int64_t now_ns) const noexcept;
  // Lets go: the last push fades out from `now_ns` (kReleasing), or at once if there is none.
  void Release(std::int64_t now_ns) noexcept;
  // The tip more than ContactTracker::kDeepTouchDown_m past the touched face's plane.
  bool PressedIn(const std::array<double, 3>& tip_m) const noexcept;
  // What is left of a released push: 1 → 0 by a smoothstep over release_ns_ (kRelease_ns, or
  // longer for a push too large to fade that fast: kReleaseRate_n_per_ns).
  double ReleaseScale(std::int64_t now_ns) const noexcept;
  // How much of what a pause held back is still to be given back (CatchUp): 1 → 0 by a
  // smoothstep over the catch-up, 0 outside one.
  double CatchUpLag(std::int64_t now_ns) const noexcept;
  // The push the object gets and the user feels back, from the spring's `touch` at the step's
  // end: ramped in, or brought back from the push held over a pause (CatchUp: the spring anchored
  // where it gave that push, the anchor returning to the tool).
  std::array<double, 3> Rendered(const ProxyContact::Result& touch, std::int64_t now_ns) noexcept;
  // `push` with its tangential part at most μ_s times its normal part, and none if it would pull;
  // what a wall holds (the proxy at its foot, ProxyContact::Result::wall_holds) is kept whole.
  std::array<double, 3> InsideFrictionCone(const std::array<double, 3>& push,
                                           const std::array<bool, 3>& wall_holds) const noexcept;
  // One primary substep's push, from the state at its end (EndOfStepLoad): the proxy moved for
  // the tool at `tool_m`, the push rendered and spread over the face (zero unless engaged).
  class SubstepPush final : public EndOfStepLoad {
   public:
    SubstepPush(SlidingContact& contact, std::int64_t now_ns)
        : contact_(contact), now_ns_(now_ns) {}
    void Load(const Eigen::VectorXd& predicted, std::span<const double> compliance,
              std::span<double> load) noexcept override;
    std::array<double, 3> tool_m{};
    std::array<double, 3> push_n{};  ///< what it pushed, N

   private:
    SlidingContact& contact_;
    std::int64_t now_ns_;
  };
  // After a period's steps: where the regions should go (following the proxy).
  void AfterPeriod() noexcept;

  ContactObject object_;
  ContactSettings settings_;
  std::int64_t ramp_ns_ = 0;
  State state_ = State::kAwaitLiftOff;
  std::optional<ProxyContact> proxy_;           // on the bound regions' primary
  LatticeIndex bound_centre_{};                 // the bound regions' centre
  std::array<double, 3> tool_{}, last_tool_{};  // this period's tip and the last period's
  std::array<double, 3> stepped_tool_{};  // the tool the regions' last substep had (lag included)
  std::array<double, 3> inward_{};              // the touched face's
  double face_m_ = 0;                           // where its plane is along its normal's axis, m
  std::optional<LatticeIndex> wanted_;
  bool following_ = false;           // the regions should follow the proxy (onto wanted_)
  bool out_of_region_ = false;       // the proxy slid out of the primary: nothing pushed
  std::int64_t ramp_start_ns_ = -1;  // the force ramps in from here (−1: no ramp)
  std::int64_t catch_up_ns_ = -1;    // the push comes back from held_push_ from here (−1: none)
  std::array<double, 3> last_push_{};  // the last period's push (the one a pause holds)
  std::array<double, 3> held_push_{};  // the push a pause held, come back from (CatchUp)
  std::array<double, 3> pushed_n_{};   // the last substep's push: a release fades it out
  // Let go into a wall: how deep a way out through it may be to touch it again (0: none).
  double wall_within_m_ = 0;
  std::array<double, 3> wall_inward_{};  // … and that wall's face's inward normal
  std::int64_t release_start_ns_ = 0;
  std::int64_t release_ns_ = kRelease_ns;  // how long this release's fade takes
  // Bind counts the regions bound (the primary reads the count only on regions that are its
  // own); a release spreads its push only on the ones that push was pushed on.
  std::uint64_t bindings_ = 0, pushed_binding_ = 0;  // that pushed_n_ was pushed on
  // Where the catching-up spring pulls from, less the tool (Rendered), once its first push is set.
  std::array<double, 3> catch_up_offset_m_{};
  // How far the tool moved while the regions stood still (CatchUp): the proxy's tool lags by it,
  // less and less over the catch-up.
  std::array<double, 3> catch_up_tool_m_{};
  bool catch_up_anchored_ = false;
  std::int64_t catch_up_duration_ns_ = 0;
};

}  // namespace hapticsim
