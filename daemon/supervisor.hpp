#pragma once

#include <limits>
#include <optional>
#include <string>

#include "core/errormap/error_map.hpp"
#include "core/scene/scene.hpp"

namespace hapticsim {

/**
 * An adaptive configuration the supervisor can choose: the three of the scene's adaptivity
 * settings it varies (the rest — shells, support layers, the exchange — stay the scene's, and so
 * does outer_rate but at equal rates: AtEqualRates). Defaults: the scene's own
 * (AdaptivitySettings), so that one quantity has one default.
 */
struct RegionConfiguration {
  int primary_size = kDaemonPrimarySize;
  int secondary_lod = AdaptivitySettings{}.secondary_lod;
  double secondary_rate_hz = AdaptivitySettings{}.secondary_rate_hz;
  double outer_rate_hz = 0;  ///< the shells beyond the first, Hz; 0: the scene's outer_rate
  bool operator==(const RegionConfiguration&) const = default;
  /** The primary size the daemon starts from when its scene names none. */
  static constexpr int kDaemonPrimarySize = 3;
};

/**
 * `configuration` with every secondary shell at the scene's primary rate: where the runaway watch
 * moves regions that ran away. Only then is the exchange monolithic central difference, stable
 * by each region's own limit; with the first shell alone at the primary rate, an outer shell at
 * its own rate still ran away (`hapticsim stress` seed 1, cases 388, 390, 470 and 972, two
 * shells, in the order hapticsimd's threads step them; docs/regions.md).
 */
RegionConfiguration AtEqualRates(const Scene& scene, RegionConfiguration configuration);

/** "primary_size 3, secondary_lod 2, secondary_rate 1000 Hz" (and ", outer_rate 1000 Hz" where
 *  set): as logs and errors name it. */
std::string DescribeConfiguration(const RegionConfiguration& configuration);
/** "contact node (ix, iy, iz)", as the log and the errors name a node. */
std::string DescribeContactNode(const LatticeIndex& node);

struct SupervisorDecision {
  RegionConfiguration configuration;
  bool have_map = false;
  double error_percent = -1;  ///< looked-up worst magnitude error, % (-1 without a map)
  bool target_met = false;
  bool clamped = false;       ///< the scene is outside the map on some axis
  double cost_us_per_ms = 0;  ///< mean measured cost in the map (0 without a map)
  int candidates_built = 0;   ///< candidates whose regions were built to check them
  std::string reason;         ///< one line for the log
};

/**
 * Why the daemon cannot use a grid map with its scene, or "" when it can: the lookup must take
 * every axis (at most ErrorLookup::kMaxAxisValues values), and every axis value must be one its
 * scene key accepts (a primary size of 1e300 is no configuration). The message names the key.
 * Scattered maps have no lookup and are left to ChooseConfiguration (it runs without them).
 */
std::string MapProblem(const Scene& scene, const ErrorMap& map);

/**
 * Picks the cheapest configuration (by the map's measured cost) whose looked-up error meets
 * `target_percent`; when none does, the one with the least error, target_met = false. A
 * configuration the map measured unstable or diverged is never chosen. The error is looked up
 * for the scene's material and contact node (the daemon passes the node its regions are centred
 * on) with the input frequency and amplitude unknown (their worst case over the map); for a
 * sliding tool the worst over the mapped nodes within LookaheadNodes of it too, or, where no
 * configuration is usable over all of them, at the node alone. Without a map: the scene's own
 * configuration. A map with a MapProblem counts as none. `pinned`: only that configuration.
 *
 * Stability is not estimated (docs/regions.md, "Stable by construction"): every region steps
 * within its own limit (its substeps see to it), the interface controllers hold the coupling's
 * energy, the runaway watch takes the regions to equal rates should their state outgrow what the
 * energy balance allows, and the port guard bounds the force meanwhile. A candidate is only
 * refused when its regions cannot be built on the scene (a primary region covering the object).
 * `below_cost_us_per_ms`: only configurations the map measured cheaper than this (deadlines
 * before accuracy, when the running one keeps missing them).
 * @throws Error when no candidate's regions can be built (or none is cheaper, with a ceiling).
 */
SupervisorDecision ChooseConfiguration(
    const Scene& scene, const ErrorMap* map, double target_percent,
    const std::optional<RegionConfiguration>& pinned,
    double below_cost_us_per_ms = std::numeric_limits<double>::infinity());

/** The map's error for a configuration running centred on one contact node. */
struct NodeError {
  bool usable = false;        ///< false: the map has no finite error there (unstable or missing)
  double error_percent = -1;  ///< worst magnitude error, % (as ChooseConfiguration looks it up)
  bool clamped = false;       ///< the node (or the material) is outside the map
};

/**
 * Looks up `configuration`'s error with the regions centred on `node`, the input unknown as in
 * ChooseConfiguration: between mapped contact nodes the error is interpolated, beyond them it is
 * the nearest edge's, flagged clamped. `reach_nodes` > 0: the worst over the mapped nodes within
 * that many of `node` along each axis, as well (LookaheadNodes). Does not throw (a map it cannot
 * look up: not usable).
 */
NodeError LookupErrorAt(const ErrorMap& map, const Scene& scene,
                        const RegionConfiguration& configuration, const LatticeIndex& node,
                        int reach_nodes = 0);

/**
 * How far ahead of the contact node, in nodes along each axis, a configuration is judged: a
 * sliding tool takes the regions on across the face node by node (ProxyWantsPrimaryAt), and a
 * configuration chosen for the node under it alone is, a node or two on, one the map calls
 * diverged or over the target there (the phantom's map: 4 of 6 configurations diverged or over
 * 2 % somewhere along the stroked row). Judged over the nodes ahead, a choice lasts while the
 * tool slides, and the next is made before the regions reach what the map says they cannot do.
 * A tool that sticks to its node: 0.
 */
inline constexpr int kLookaheadNodes = 2;
int LookaheadNodes(const Scene& scene);

/** The scene with `configuration` as its adaptivity. */
Scene SceneWith(const Scene& scene, const RegionConfiguration& configuration);

/** … and its regions centred on the surface node `node` (input.contact_node). */
Scene SceneWith(const Scene& scene, const RegionConfiguration& configuration,
                const LatticeIndex& node);

/** A configuration checked around one contact node. */
struct CentredConfiguration {
  RegionConfiguration configuration;  ///< the one asked for, or its equal-rate fallback
  bool verified = false;              ///< checked around the node (false: moved there unchecked)
  bool fell_back = false;             ///< at equal rates: the one asked for ran away there
};

/**
 * Checks that `configuration` can run with its regions centred on `node`: the node is a surface
 * node the tool may touch (not a support) and the regions can be built around it (their shapes
 * change near the object's edges and corners). No stability estimate: see ChooseConfiguration.
 * @throws Error naming what is wrong.
 */
CentredConfiguration VerifyCentredOn(const Scene& scene, const RegionConfiguration& configuration,
                                     const LatticeIndex& node);

}  // namespace hapticsim
