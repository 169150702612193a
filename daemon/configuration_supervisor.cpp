#include "daemon/configuration_supervisor.hpp"

#include <spdlog/fmt/fmt.h>
#include <spdlog/spdlog.h>

#include <vector>

#include "core/error.hpp"
#include "daemon/command_check.hpp"

namespace hapticsim {

std::int32_t DecisionFlags(const SupervisorDecision& d) {
  std::int32_t flags = 0;
  if (!d.have_map) flags |= force_flags::kNoErrorMap;
  if (d.have_map && !d.target_met) flags |= force_flags::kErrorTargetExceeded;
  if (d.clamped) flags |= force_flags::kLookupClamped;
  return flags;
}

ConfigurationSupervisor::ConfigurationSupervisor(const Scene& scene, MapState map,
                                                 double target_percent,
                                                 const SupervisorDecision& first, HapticLoop& loop)
    : scene_(scene),
      loop_(loop),
      map_(std::move(map)),
      target_(target_percent),
      decision_(first),
      chosen_for_nodes_{loop.centre_node()},
      mover_(scene, {{first.configuration, true, false}, loop.centre_node()}),
      reported_error_(first.error_percent),
      reported_target_met_(first.target_met) {
  loop_.SetErrorState(decision_.error_percent, DecisionFlags(decision_));
}

void ConfigurationSupervisor::RequestStop() {
  chooser_.RequestStop();
  mover_.RequestStop();
}

SupervisorDecision ConfigurationSupervisor::Shown() const {
  SupervisorDecision shown = decision_;
  shown.configuration = active();
  shown.error_percent = reported_error_;  // for the node the regions are centred on
  shown.target_met = reported_target_met_;
  return shown;
}

// The scene as the regions run it: centred on the node the tool last touched. A choice is made
// for that node — its error looked up there, its regions built around it.
Scene ConfigurationSupervisor::SceneAtCentre() const {
  Scene scene = scene_;
  scene.input.contact_node = loop_.centre_node();
  return scene;
}

void ConfigurationSupervisor::StartChoice(const std::optional<RegionConfiguration>& pin) {
  choice_pin_ = pin;
  chosen_for_nodes_.insert(loop_.centre_node());
  chooser_.Submit(
      [scene = SceneAtCentre(), m = map_.map, target = target_, pin, ceiling = cost_ceiling_] {
        return ChooseConfiguration(scene, m.get(), target, pin, ceiling);
      });
}

// A new target, map or pin: every node may be chosen for again, at any cost.
void ConfigurationSupervisor::ChooseAgain(const std::optional<RegionConfiguration>& pin) {
  chosen_for_nodes_.clear();
  cost_ceiling_ = std::numeric_limits<double>::infinity();
  choice_for_overload_ = false;
  StartChoice(pin);
}

// The decision's error looked up again for the configuration running and the node the regions
// are centred on — interpolated between mapped contact nodes, the nearest mapped one's beyond
// them (flagged clamped). Where the map has no finite error the status says -1 % and "target
// exceeded": accuracy unknown is not accuracy met.
void ConfigurationSupervisor::ReportError() {
  std::int32_t flags = DecisionFlags(decision_) | (pending_ ? force_flags::kReconfiguring : 0);
  double error = decision_.error_percent;
  if (decision_.have_map && map_.map) {
    const NodeError here = LookupErrorAt(*map_.map, scene_, active(), loop_.centre_node());
    error = here.error_percent;
    flags &= ~(force_flags::kLookupClamped | force_flags::kErrorTargetExceeded);
    if (here.clamped) flags |= force_flags::kLookupClamped;
    if (!here.usable || error > target_) flags |= force_flags::kErrorTargetExceeded;
  }
  reported_error_ = error;
  reported_target_met_ = decision_.have_map && !(flags & force_flags::kErrorTargetExceeded);
  loop_.SetErrorState(error, flags);
}

// Around the node the regions moved to, the configuration may miss the target that it met where
// it was chosen (a box cut by the object's edge, a coarser neighbourhood), or, for a sliding tool,
// miss it a node or two ahead (LookaheadNodes): choose again for that node, once per node. What
// is chosen switches like any other.
void ConfigurationSupervisor::ChooseForCentreIfMissed() {
  const LatticeIndex& node = loop_.centre_node();
  if (!decision_.have_map || !map_.map || pinned_ || chooser_.busy() || pending_ ||
      chosen_for_nodes_.count(node)) {
    return;
  }
  const int reach = LookaheadNodes(scene_);
  if (reported_target_met_) {
    if (reach == 0) return;
    const NodeError ahead = LookupErrorAt(*map_.map, scene_, active(), node, reach);
    if (ahead.usable && ahead.error_percent <= target_) return;
    spdlog::info(
        "within {} nodes of contact node ({}, {}, {}) the looked-up error of {} is {} against "
        "the target {} %: choosing again before the tool slides there",
        reach, node[0], node[1], node[2], DescribeConfiguration(active()),
        ahead.usable ? fmt::format("{:.3g} %", ahead.error_percent) : std::string("unknown"),
        target_);
  } else {
    spdlog::warn(
        "around contact node ({}, {}, {}) the looked-up error of {} is {} % against the target "
        "{} %: choosing again for this node",
        node[0], node[1], node[2], DescribeConfiguration(active()),
        reported_error_ < 0 ? std::string("unknown") : fmt::format("{:.3g}", reported_error_),
        target_);
  }
  StartChoice(std::nullopt);
}

// A replacement of the regions that held the supervisor's thread long (commands wait meanwhile,
// and a touch is held or waits for the new regions) is said, with where the time went.
void ConfigurationSupervisor::SayIfSlow(const HapticLoop::ReplacementTimes& took) {
  if (took.total_s < kSlowReplacement_s) return;
  spdlog::warn(
      "replacing the regions took {:.3f} s (building them {:.3f} s, the primary thread pausing "
      "{:.3f} s, the old secondary threads stopping {:.3f} s); commands waited meanwhile",
      took.total_s, took.build_s, took.pause_s, took.join_s);
}

void ConfigurationSupervisor::RestartFromRest(const char* why) {
  try {
    loop_.Reconfigure(SceneWith(scene_, active(), loop_.centre_node()));
    SayIfSlow(loop_.last_replacement());
  } catch (const Error& e) {
    // Only a hung primary thread gets here (the scene is the running one): the watchdog's
    // pings stop and systemd restarts the daemon.
    spdlog::error("{}: restarting the regions failed: {}", why, e.what());
  }
}

void ConfigurationSupervisor::OnReload(std::optional<double> target_percent, MapState reloaded) {
  if (target_percent) target_ = *target_percent;
  if (reloaded.map || reloaded.path.empty()) map_ = std::move(reloaded);
  ReportError();  // the new target or map, until the new choice replaces the decision
  ChooseAgain(pinned_);
}

std::string ConfigurationSupervisor::SetErrorTarget(double target_percent,
                                                    const std::string& from) {
  target_ = target_percent;
  decision_.target_met = decision_.have_map && decision_.error_percent <= target_;
  ReportError();
  if (decision_.have_map && decision_.error_percent >= 0) {
    spdlog::info(
        "error target set to {} % by {}: the active configuration's {} % {}; choosing again",
        target_, from, decision_.error_percent, decision_.target_met ? "meets it" : "EXCEEDS it");
  } else {
    spdlog::info(
        "error target set to {} % by {}: the active configuration's error is unknown (no error "
        "map, or none for this node); choosing again",
        target_, from);
  }
  ChooseAgain(pinned_);
  return "ok: error target " + FormatReal(target_) + " %; choosing again";
}

std::string ConfigurationSupervisor::OnCommand(const command_t& command, const std::string& from) {
  const CheckedCommand checked = CheckCommand(command, PrimaryRateHz(scene_));
  switch (checked.kind) {
    case CheckedCommand::Kind::kSetErrorTarget:
      return SetErrorTarget(checked.error_target_percent, from);
    case CheckedCommand::Kind::kPinConfiguration:
      spdlog::info(
          "command PIN_CONFIGURATION from {}: verifying primary_size {}, secondary_lod {}, "
          "secondary_rate {} Hz",
          from, checked.pin.primary_size, checked.pin.secondary_lod, checked.pin.secondary_rate_hz);
      ChooseAgain(checked.pin);
      return "ok: verifying the pin (status says pinned once it runs; the log says why not)";
    case CheckedCommand::Kind::kReleaseConfiguration:
      spdlog::info("command RELEASE_CONFIGURATION from {}: choosing freely again", from);
      pinned_.reset();
      ChooseAgain(std::nullopt);
      return "ok: released; choosing freely again";
    case CheckedCommand::Kind::kReset:
      spdlog::info("command RESET from {}: the simulation restarts from rest", from);
      RestartFromRest("RESET");
      return "ok: the simulation restarts from rest";
    case CheckedCommand::Kind::kRefused:
      spdlog::warn("command from {} {}", from, checked.refusal);
      return "refused: " + checked.refusal;
  }
  return "refused: unknown";
}

bool ConfigurationSupervisor::Tick(std::int64_t now_ns) {
  TakeChoice();
  const bool move_soon = MoveRegions(now_ns);
  CheckOverload(now_ns);
  return move_soon;
}

void ConfigurationSupervisor::TakeChoice() {
  std::optional<BackgroundWorker<SupervisorDecision>::Outcome> outcome = chooser_.Take();
  if (!outcome) return;
  if (outcome->result) {
    SupervisorDecision chosen = std::move(*outcome->result);
    if (choice_pin_) spdlog::info("configuration pinned");
    pinned_ = choice_pin_;
    if (chosen.configuration == decision_.configuration) {
      spdlog::info("configuration kept: {}", chosen.reason);
      decision_ = chosen;
      pending_.reset();
    } else {
      spdlog::info(
          "{} configuration: {}; switching once it is checked around the contact node, carrying "
          "the object's motion over",
          pinned_ ? "pinned" : "better", chosen.reason);
      pending_ = chosen;
    }
    ReportError();
  } else {
    if (choice_for_overload_) cheapest_cost_us_per_ms_ = decision_.cost_us_per_ms;
    spdlog::error("{} failed: {}; keeping the active configuration",
                  choice_pin_ ? "pinning a configuration" : "choosing a configuration",
                  outcome->error);
  }
  choice_for_overload_ = false;
  ChooseForCentreIfMissed();  // the regions may have moved while it was being made
}

// Moving the regions — to the pending configuration, or onto the node the tool touches or hovers
// over. A new configuration around the same node switches as soon as it is checked, in contact
// too: the object's motion carries over and the force is held meanwhile (Handover::
// kCarryMotion). Onto a hovered node only after the object has settled, as the regions restart
// from rest there. A touch on another node moves them at once (zero force, flagged, for the few
// periods until they are there; checked behind them), then ramps its force in; it may give up a
// check still running.
bool ConfigurationSupervisor::MoveRegions(std::int64_t now) {
  const bool settled = (now - loop_.last_contact_ns()) * 1e-9 >= kSettleBeforeReconfigure_s;
  const std::optional<LatticeIndex> wanted = loop_.wanted_contact_node();
  if (wanted != hover_node_) hover_node_ = wanted, hover_since_ns_ = now;
  const bool waiting = loop_.contact_waiting();
  const bool following = loop_.contact_following();  // a sliding tool: at once, motion carried
  // Where a pending configuration goes: a hovered node once the object has settled, else here.
  const LatticeIndex pending_node =
      settled ? wanted.value_or(loop_.centre_node()) : loop_.centre_node();
  // A follow gives up the check behind the last move (left behind, the proxy slides to the edge of
  // the primary, next to its interface: on the phantom the force chattered there), not a pending
  // configuration's: the proxy has the primary's reach to slide meanwhile.
  const bool interrupt = waiting || (following && !mover_.busy_with_pending());
  if (!mover_.busy() || (interrupt && mover_.may_interrupt())) {
    std::optional<RegionsMover::Request> request;
    if (pending_ && !waiting && !following) {
      request = {pending_->configuration, pending_node, true, false};
    } else if (wanted && *wanted != loop_.centre_node() &&
               (waiting || following ||
                (settled && (now - hover_since_ns_) * 1e-9 >= kHoverBeforeRecentre_s))) {
      // A follow keeps the configuration running (equal rates where the runaway watch moved it).
      const RegionConfiguration& configuration =
          following ? mover_.placement().centred.configuration : decision_.configuration;
      request = {configuration, *wanted, false, waiting || following, following};
    }
    if (request && mover_.may_ask(*request)) mover_.Ask(*request, now);
  }
  if (loop_.runaways() > runaways_seen_) {  // off a configuration whose state outgrew its balance
    runaways_seen_ = loop_.runaways();
    mover_.OnRunaway(now, loop_.last_runaway());  // the Poll below moves them
  }
  try {
    if (const std::optional<RegionsMover::Outcome> moved = mover_.Poll(now)) {
      ApplyMove(*moved, now);
    }
  } catch (const Error& e) {
    spdlog::error("moving the regions failed: {}; they stay where they are", e.what());
    if (pending_ && !mover_.may_ask({pending_->configuration, pending_node, true})) {
      pending_.reset();  // refused around this node: not asked again
    }
    ReportError();
  }
  // A touch waiting for its regions, or a tool about to touch another node, is served within a
  // few milliseconds (the move is at the next tick); otherwise the tick is slower.
  return wanted && *wanted != loop_.centre_node() &&
         mover_.may_ask({decision_.configuration, *wanted, false, true});
}

// The regions where the mover says: moved now (checked before, or to be checked behind them),
// demoted to equal rates where they ran away, or moved back where they cannot run.
void ConfigurationSupervisor::ApplyMove(const RegionsMover::Outcome& moved, std::int64_t now) {
  using Kind = RegionsMover::Outcome::Kind;
  spdlog::log(moved.kind == Kind::kMoveBack ? spdlog::level::err
              : moved.kind == Kind::kDemote ? spdlog::level::warn
                                            : spdlog::level::info,
              "{}", moved.Describe());
  if (moved.moves()) {
    try {
      loop_.Reconfigure(SceneWith(scene_, moved.to.centred.configuration, moved.to.node),
                        moved.CarriesMotionFrom(loop_.centre_node())
                            ? HapticLoop::Handover::kCarryMotion
                            : HapticLoop::Handover::kRampIn);
      SayIfSlow(loop_.last_replacement());
    } catch (const Error&) {
      mover_.NotApplied(moved);  // a demotion or a move back is tried again at the next tick
      throw;
    }
  }
  mover_.Applied(moved);
  if (!moved.moves()) return;
  // The pending decision this move was asked for: a newer choice may have replaced or dropped it
  // while the move was being verified; then it is not applied.
  if (moved.request.applies_pending && pending_ &&
      pending_->configuration == moved.request.configuration) {
    decision_ = *pending_;
    pending_.reset();
    spdlog::info("reconfigured: {}", decision_.reason);
  }
  overload_.Reset(now);
  ReportError();
  ChooseForCentreIfMissed();
}

// Deadlines before accuracy: a region that keeps missing them gets a cheaper configuration (the
// map's measured costs), switched like any other.
void ConfigurationSupervisor::CheckOverload(std::int64_t now) {
  std::vector<double> rates_hz;
  for (int r = 0; r < loop_.regions().num_regions(); ++r) {
    rates_hz.push_back(loop_.regions().schedule(r).rate_hz);
  }
  const int region = overload_.Check(now, rates_hz);
  if (region < 0) return;
  const std::string name = loop_.regions().partition().RegionName(region);
  const bool nothing_cheaper = decision_.cost_us_per_ms == cheapest_cost_us_per_ms_;
  if (decision_.have_map && !pinned_ && !chooser_.busy() && !nothing_cheaper) {
    spdlog::error("{}", ChoosingCheaperLine(name, overload_.last_misses(), rates_hz[region],
                                            decision_.cost_us_per_ms));
    cost_ceiling_ = decision_.cost_us_per_ms;
    choice_for_overload_ = true;
    StartChoice(std::nullopt);
  } else if (now - last_overload_line_ns_ > 60'000'000'000) {
    last_overload_line_ns_ = now;
    spdlog::error("{}", CannotChooseCheaperLine(name, overload_.last_misses(),
                                                pinned_              ? "a configuration is pinned"
                                                : nothing_cheaper    ? "the map has nothing cheaper"
                                                : decision_.have_map ? "a choice is being made"
                                                                     : "no error map"));
  }
}

}  // namespace hapticsim
