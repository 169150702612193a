#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <tuple>

#include "daemon/background_worker.hpp"
#include "daemon/supervisor.hpp"

namespace hapticsim {

/**
 * The supervisor's side of moving the regions — to another configuration or to another contact
 * node. The move itself is HapticLoop::Reconfigure, done by the caller with what Poll returns.
 *
 * A touch does not wait. The regions move onto a touched node at once, with their interface
 * controllers and port limits on (docs/regions.md), and the coupled stability of the bare
 * exchange around the node is verified behind them (VerifyCentredOn, a fraction of a second on
 * the paper's cube) on a background thread of its own, made once, so the supervisor's tick never
 * waits and no request makes a thread. Should the verdict be that the configuration is unstable
 * around the node, Poll says to demote the regions there to their secondaries at the primary rate;
 * the port guard bounds what reaches the hand until then. A configuration change (asked out of
 * contact, with nobody waiting) is still verified before it moves. Verdicts are kept per
 * configuration and node, so a node touched before moves straight to its verified configuration.
 */
class RegionsMover {
 public:
  struct Request {
    RegionConfiguration configuration;
    LatticeIndex node{};
    bool applies_pending = false;  ///< the supervisor's pending configuration change
  };
  struct Outcome {
    enum class Kind {
      kMoveUnverified,  ///< move now; its coupling is being verified behind it
      kMoveVerified,    ///< move now; verified (before, or by an earlier touch on the node)
      kConfirmed,       ///< the regions moved unverified are stable there: nothing to move
      kDemote,          ///< they are not: move them to `centred` (the secondaries at equal rates)
    };
    Kind kind = Kind::kMoveVerified;
    Request request;
    CentredConfiguration centred;  ///< spectral_radius −1 while unverified
    double elapsed_ms = 0;         ///< from the request to this outcome
    bool moves() const { return kind != Kind::kConfirmed; }
  };

  explicit RegionsMover(const Scene& scene) : scene_(scene) {}

  /** Shutting down: the verifying thread stops after the verification it runs, if any. */
  void RequestStop() { verifier_.RequestStop(); }

  /** True from Ask until Poll has returned its last outcome (a verdict behind a move included). */
  bool busy() const { return asked_.has_value(); }
  /** True while regions moved unverified wait for their verdict. */
  bool verifying_behind() const { return asked_ && behind_; }
  /** When its verification running now started (CLOCK_MONOTONIC ns), 0 when none runs. */
  std::int64_t running_since_ns() const { return verifier_.running_since_ns(); }
  /** False for a configuration and node found unstable (or invalid) before: not asked again. */
  bool may_ask(const Request& request) const { return !refused_.count(KeyOf(request)); }
  /**
   * Starts a move: a touch's at once (the next Poll returns it), a configuration change once
   * verified.
   */
  void Ask(const Request& request, std::int64_t now_ns);
  /**
   * The next outcome, once there is one.
   * @throws Error when the node cannot be touched (off the surface, a support: at once) or the
   *         configuration is unstable around it even at equal rates (remembered as refused). For a
   *         move made unverified, the regions it moved must then be moved away.
   */
  std::optional<Outcome> Poll(std::int64_t now_ns);

 private:
  using Key = std::tuple<int, int, double, int, int, int>;
  static Key KeyOf(const Request& r) {
    return {r.configuration.primary_size,
            r.configuration.secondary_lod,
            r.configuration.secondary_rate_hz,
            r.node[0],
            r.node[1],
            r.node[2]};
  }
  std::optional<Outcome> TakeVerdict(std::int64_t now_ns);

  Scene scene_;
  std::map<Key, CentredConfiguration> verdicts_;
  std::set<Key> refused_;
  std::optional<Request> asked_;
  std::int64_t asked_ns_ = 0;
  bool behind_ = false;  // asked_ was moved unverified: its verdict is still to come
  BackgroundWorker<CentredConfiguration> verifier_{"hsim-verify"};
  std::optional<Outcome> ready_;  // an outcome known at Ask, waiting for Poll
  std::string refusal_;           // why the node asked for cannot be touched, for Poll
};

}  // namespace hapticsim
