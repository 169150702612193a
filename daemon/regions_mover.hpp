#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <tuple>

#include "daemon/background_worker.hpp"
#include "daemon/supervisor.hpp"

namespace hapticsim {

/**
 * The supervisor's side of moving the regions — to another configuration or to another contact
 * node. Before the regions move, their coupled stability around the node is verified
 * (VerifyCentredOn, a fraction of a second on the paper's cube) on a background thread of its
 * own, made once, so the supervisor's tick never waits and no request makes a thread; verdicts
 * are kept per configuration and node, so a node touched before moves at once. The move itself is
 * HapticLoop::Reconfigure, done by the caller.
 */
class RegionsMover {
 public:
  struct Request {
    RegionConfiguration configuration;
    LatticeIndex node{};
    bool applies_pending = false;  ///< the supervisor's pending configuration change
  };
  struct Verified {
    Request request;
    CentredConfiguration centred;
    double verify_ms = 0;  ///< from the request to the verdict
  };

  explicit RegionsMover(const Scene& scene) : scene_(scene) {}

  /** Shutting down: the verifying thread stops after the verification it runs, if any. */
  void RequestStop() { verifier_.RequestStop(); }

  /** True from Ask until Poll has returned its verdict. */
  bool busy() const { return asked_.has_value(); }
  /** When its verification running now started (CLOCK_MONOTONIC ns), 0 when none runs. */
  std::int64_t running_since_ns() const { return verifier_.running_since_ns(); }
  /** False for a configuration and node found unstable (or invalid) before: not asked again. */
  bool may_ask(const Request& request) const { return !refused_.count(KeyOf(request)); }
  /** Starts verifying; a verdict already known is returned by the next Poll. */
  void Ask(const Request& request, std::int64_t now_ns);
  /**
   * The verdict once it is there.
   * @throws Error when the configuration is unstable around the node (remembered as refused).
   */
  std::optional<Verified> Poll(std::int64_t now_ns);

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

  Scene scene_;
  std::map<Key, CentredConfiguration> verdicts_;
  std::set<Key> refused_;
  std::optional<Request> asked_;
  std::int64_t asked_ns_ = 0;
  BackgroundWorker<CentredConfiguration> verifier_{"hsim-verify"};
  std::optional<CentredConfiguration> known_;  // a cached verdict waiting for Poll
};

}  // namespace hapticsim
