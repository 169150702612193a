#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <tuple>
#include <utility>

#include "core/regions/async_regions.hpp"
#include "daemon/background_worker.hpp"
#include "daemon/supervisor.hpp"

namespace hapticsim {

/**
 * The supervisor's side of moving the regions — to another configuration or to another contact
 * node — and where they are now. The move itself is HapticLoop::Reconfigure, done by the caller
 * with what Poll returns.
 *
 * A touch does not wait. The regions move onto a touched node at once, with their interface
 * controllers, port limits and runaway watch on (docs/regions.md), and what a move needs — the
 * node is one the tool may touch, the regions can be built around it (VerifyCentredOn) — is
 * checked behind them on a background thread of its own, made once, so the supervisor's tick
 * never waits and no request makes a thread. No stability estimate is made: should the regions'
 * state outgrow what the energy balance allows, the loop's runaway watch says so (OnRunaway) and
 * the regions go to equal rates there. Should the check refuse the node, Poll says to move them
 * back to where they were last checked; the port guard bounds what reaches the hand meanwhile. A
 * configuration change (asked out of contact, with nobody waiting) and a hovering tool's move
 * are checked before they move. Checks are kept per configuration and node, so a node touched
 * before moves straight there. A touch elsewhere may give up a check still running (the regions
 * leave that node anyway).
 */
class RegionsMover {
 public:
  struct Request {
    RegionConfiguration configuration;
    LatticeIndex node{};
    bool applies_pending = false;  ///< the supervisor's pending configuration change
    bool touch_waits = false;      ///< a touch waits for it: move at once, verify behind
    /// A sliding tool's regions following its proxy (HapticLoop::contact_following): moved at
    /// once like a waiting touch, the object's motion carried onto the new node.
    bool follows_proxy = false;
  };
  /** Where the regions run: a configuration, centred on a node. */
  struct Placement {
    CentredConfiguration centred;  ///< verified false while the check behind a move runs
    LatticeIndex node{};
  };
  struct Outcome {
    enum class Kind {
      kMoveUnverified,  ///< move now; checked behind it
      kMoveVerified,    ///< move now; checked (before, or by an earlier touch on the node)
      kConfirmed,       ///< the regions moved unchecked can run there: nothing to move
      kDemote,          ///< they ran away (OnRunaway): the secondaries at equal rates there
      kMoveBack,        ///< they cannot run there: back to where they were last checked
    };
    Kind kind = Kind::kMoveVerified;
    Request request;
    Placement to;                        ///< where the regions go (or stay, kConfirmed)
    double elapsed_ms = 0;               ///< from the request to this outcome
    std::string why_not;                 ///< kMoveBack: why the node was refused
    bool runaway = false;                ///< kDemote for the runaway watch (OnRunaway)
    RunawayEnergies runaway_energies{};  ///< what the watch measured, for the log
    bool moves() const { return kind != Kind::kConfirmed; }
    /**
     * Whether the new regions start from the object's motion (HapticLoop::Handover::
     * kCarryMotion, a switch in contact): a verified configuration on the node they are centred
     * on now, or a move that follows a sliding tool's proxy. Onto another node otherwise, or
     * demoted or moved back from a configuration that ran away or cannot run (whose motion is not
     * to be kept), they start from rest, a touch ramped in.
     */
    bool CarriesMotionFrom(const LatticeIndex& centre) const {
      if (request.follows_proxy)
        return kind == Kind::kMoveVerified || kind == Kind::kMoveUnverified;
      return kind == Kind::kMoveVerified && to.node == centre;
    }
    /** The log line that says what happened. */
    std::string Describe() const;
  };

  /** How a configuration is verified around a node: VerifyCentredOn, or — in a test of what
   *  the mover does with a verdict no scene here gives — a stand-in for it. */
  using Verifier = std::function<CentredConfiguration(const Scene&, const RegionConfiguration&,
                                                      const LatticeIndex&)>;

  /** `at`: where the regions run at start (verified). */
  RegionsMover(const Scene& scene, const Placement& at, Verifier verify = VerifyCentredOn);

  /** Shutting down: the verifying thread stops after the verification it runs, if any. */
  void RequestStop() { verifier_.RequestStop(); }

  /** Where the regions run, as of the last outcome the caller applied (Applied). */
  const Placement& placement() const { return placed_; }

  /** True from Ask until Poll has returned its last outcome (a verdict behind a move included). */
  bool busy() const { return asked_.has_value(); }
  /** True while what it is busy with may be given up for a touch: a verification (behind a
   *  move, or before a configuration change), not an outcome still to be applied. */
  bool may_interrupt() const { return busy() && !ready_; }
  /** True while what it is busy with is the supervisor's pending configuration change. */
  bool busy_with_pending() const { return asked_ && asked_->applies_pending; }
  /** When its verification running now started (CLOCK_MONOTONIC ns), 0 when none runs. */
  std::int64_t running_since_ns() const { return verifier_.running_since_ns(); }
  /** False for a configuration and node that ran away (or were refused) before: not asked again. */
  bool may_ask(const Request& request) const { return !refused_.count(KeyOf(request)); }
  /**
   * Starts a move: one a touch waits for at once (the next Poll returns it), any other once
   * verified. Asked while busy, it replaces what the mover was doing (see may_interrupt).
   */
  void Ask(const Request& request, std::int64_t now_ns);
  /**
   * The next outcome, once there is one; placement() follows it.
   * @throws Error when a move is refused before anything moved: the node cannot be touched (off
   *         the surface, a support) or the regions cannot be built around it (both at once), or a
   *         configuration change cannot run around it. Remembered as
   *         refused; the regions stay where they are.
   */
  std::optional<Outcome> Poll(std::int64_t now_ns);
  /**
   * The loop's runaway watch fired on the regions as placed (HapticLoop::runaways): their state
   * outgrew what the energy balance allows, which the interface controllers cannot see. Returns
   * the move to the secondaries at the primary rate there (kDemote, from rest with the touch
   * ramped in); from then on a request for that configuration around that node moves straight
   * to equal rates there. Already at equal rates (monolithic central difference, stable by each
   * region's own limit), the same regions start again from rest. Gives up whatever the mover was
   * doing; the next Poll returns the move. `measured`: what the watch saw, for the log line.
   */
  void OnRunaway(std::int64_t now_ns, const RunawayEnergies& measured = {});
  /**
   * The caller moved the regions as `outcome` said (or, kConfirmed, left them): placement()
   * follows. An outcome that fails to apply (HapticLoop::Reconfigure threw) is given back with
   * NotApplied: a demotion or a move back is then returned again by the next Poll; a move is
   * dropped, with the verification behind it.
   */
  void Applied(const Outcome& outcome);
  void NotApplied(const Outcome& outcome);

 private:
  using Key = std::tuple<int, int, double, double, int, int, int>;
  static Key KeyOf(const Request& r) {
    return {r.configuration.primary_size,
            r.configuration.secondary_lod,
            r.configuration.secondary_rate_hz,
            r.configuration.outer_rate_hz,
            r.node[0],
            r.node[1],
            r.node[2]};
  }
  std::optional<Outcome> TakeVerdict(std::int64_t now_ns);

  Scene scene_;
  Placement placed_, last_verified_;
  Verifier verify_;
  std::map<Key, CentredConfiguration> verdicts_;
  std::set<Key> refused_;
  std::optional<Request> asked_;
  std::int64_t asked_ns_ = 0;
  bool behind_ = false;  // asked_ was moved unverified: its verdict is still to come
  BackgroundWorker<CentredConfiguration> verifier_{"hsim-verify"};
  std::optional<Outcome> ready_;  // an outcome known at Ask (or to retry), waiting for Poll
  std::string refusal_;           // why the node asked for cannot be touched, for Poll
};

}  // namespace hapticsim
