#pragma once

#include <cstdint>
#include <limits>
#include <optional>
#include <set>
#include <string>

#include "daemon/background_worker.hpp"
#include "daemon/error_map_loading.hpp"
#include "daemon/haptic_loop.hpp"
#include "daemon/overload_watch.hpp"
#include "daemon/regions_mover.hpp"
#include "daemon/supervisor.hpp"
#include "hapticsim/command_t.hpp"

namespace hapticsim {

/**
 * The daemon's supervisor: which configuration the regions run and where they are centred.
 * It chooses from the error map the cheapest configuration meeting the error target
 * (ChooseConfiguration, on a background thread), switches to it once it is checked around the
 * contact node — in contact too, carrying the object's motion over — moves the regions onto the
 * node the tool touches or hovers over (RegionsMover), takes regions that ran away to equal
 * rates, chooses cheaper when a region keeps missing its deadlines (deadlines before accuracy),
 * and keeps the error the loop reports for the configuration and node that run.
 *
 * Commands (OnCommand), a reload (OnReload) and the periodic Tick all come on one thread, the
 * daemon's supervisor thread; none of them waits for a choice or a check being made.
 */
class ConfigurationSupervisor {
 public:
  /** `first`: the decision `loop` was built with (ChooseConfiguration for the scene's node). */
  ConfigurationSupervisor(const Scene& scene, MapState map, double target_percent,
                          const SupervisorDecision& first, HapticLoop& loop);

  /**
   * A command from LCM or hapticsim ctl (`from` names who sent it, for the log), checked and
   * acted on: a new error target or pin is chosen for on the background thread (the answer says
   * so at once), a release chooses freely again, a reset restarts the regions from rest. Returns
   * the answer in words: "ok: …" or "refused: …".
   */
  std::string OnCommand(const command_t& command, const std::string& from);
  /** SIGHUP: `target_percent` (unless nullopt: the config was refused) and `reloaded` (kept
   *  only when it holds a map, or names none) take effect; the choice is made again. */
  void OnReload(std::optional<double> target_percent, MapState reloaded);
  /** `misses` more missed periods of `region`, for the overload watch. */
  void CountMisses(int region, std::int64_t misses) { overload_.Count(region, misses); }
  /**
   * The periodic work: takes a finished choice, moves the regions where they should be, and
   * checks for overload. Returns whether a move is due soon (a touch waits, or the tool is about
   * to touch another node): then the next tick should come within a few milliseconds.
   */
  bool Tick(std::int64_t now_ns);
  /** Restarts the regions from rest where they are (a force fault, RESET): the tool must lift
   *  off before it feels force. */
  void RestartFromRest(const char* why);
  /** Shutting down: both background threads stop after their current job. */
  void RequestStop();

  /** The decision running, as the status shows it: its configuration the one placed and its
   *  error looked up for the node the regions are centred on. */
  SupervisorDecision Shown() const;
  const SupervisorDecision& decision() const { return decision_; }
  /** A choice made, waiting to switch once checked (and the tool is away from a hovered node). */
  const std::optional<SupervisorDecision>& pending() const { return pending_; }
  /** The configuration the regions run now. */
  const RegionConfiguration& active() const { return mover_.placement().centred.configuration; }
  double target_percent() const { return target_; }
  bool pinned() const { return pinned_.has_value(); }
  const std::string& map_path() const { return map_.path; }
  /** A choice is being made, or waits to be taken by Tick. */
  bool choosing() const { return chooser_.busy(); }
  /** A move is being checked, or waits to be applied by Tick. */
  bool moving() const { return mover_.busy(); }
  /** When the background jobs running now started (CLOCK_MONOTONIC ns, 0: none runs). */
  std::int64_t choice_running_since_ns() const { return chooser_.running_since_ns(); }
  std::int64_t check_running_since_ns() const { return mover_.running_since_ns(); }

  /** The hover before the regions move onto a node the tool does not touch. */
  static constexpr double kHoverBeforeRecentre_s = 0.2;  // not every node a passing tool crosses
  /** The rest after a touch before regions that restart from rest may move. */
  static constexpr double kSettleBeforeReconfigure_s = 1.0;  // e^(−d t / 2) < 1 % at d = 10 1/s
  /** A replacement of the regions this long is logged with where its time went (SayIfSlow). */
  static constexpr double kSlowReplacement_s = 0.25;

 private:
  Scene SceneAtCentre() const;
  void StartChoice(const std::optional<RegionConfiguration>& pin);
  void ChooseAgain(const std::optional<RegionConfiguration>& pin);
  void ReportError();
  void ChooseForCentreIfMissed();
  std::string SetErrorTarget(double target_percent, const std::string& from);
  void TakeChoice();
  bool MoveRegions(std::int64_t now_ns);
  void ApplyMove(const RegionsMover::Outcome& moved, std::int64_t now_ns);
  void CheckOverload(std::int64_t now_ns);
  static void SayIfSlow(const HapticLoop::ReplacementTimes& took);

  const Scene scene_;
  HapticLoop& loop_;
  MapState map_;
  double target_;
  std::optional<RegionConfiguration> pinned_;
  SupervisorDecision decision_;
  // New choices are made on one background thread (building regions takes milliseconds): the
  // tick never waits, and no command makes a thread.
  BackgroundWorker<SupervisorDecision> chooser_{"hsim-choose"};
  std::optional<RegionConfiguration> choice_pin_;  // the pin the newest choice was asked with
  std::optional<SupervisorDecision> pending_;      // chosen, waiting for the tool to be away
  bool choice_for_overload_ = false;               // the running choice is for deadlines
  // The nodes a choice was made for since the target, the map or the pin last changed: around
  // each, the supervisor chooses once. The cost ceiling an overload set holds as long (deadlines
  // before accuracy: a choice for a node does not bring the dear configuration back).
  std::set<LatticeIndex> chosen_for_nodes_;
  double cost_ceiling_ = std::numeric_limits<double>::infinity();
  // The regions run mover_.placement(): the decision's configuration, or its equal-rate fallback
  // where the decision's ran away around the node they are centred on.
  RegionsMover mover_;
  // The error the status reports (Shown): the decision's, looked up again for the configuration
  // running and the node the regions are centred on.
  double reported_error_;
  bool reported_target_met_;
  OverloadWatch overload_;  // a region missing deadlines second after second
  std::int64_t last_overload_line_ns_ = 0;
  // The cost of a configuration the map has nothing cheaper than: not asked again.
  double cheapest_cost_us_per_ms_ = -1;
  std::optional<LatticeIndex> hover_node_;  // the node the tool hovers over, and since when
  std::int64_t hover_since_ns_ = 0;
  std::int64_t runaways_seen_ = 0;
};

/** The force flags a decision gives every answer: no map, target exceeded, lookup clamped. */
std::int32_t DecisionFlags(const SupervisorDecision& decision);

}  // namespace hapticsim
