#include "daemon/supervisor.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

#include "core/error.hpp"
#include "core/errormap/error_lookup.hpp"
#include "core/regions/async_regions.hpp"
#include "core/regions/proxy_following.hpp"

namespace hapticsim {
namespace {

constexpr int kLod = static_cast<int>(MapAxis::kSecondaryLod);
constexpr int kSize = static_cast<int>(MapAxis::kPrimarySize);
constexpr int kRate = static_cast<int>(MapAxis::kSecondaryRate);

// Why regions cannot be built on `scene` as the daemon builds them, or "". Built, each region
// steps within kSubstepSafety of its own limit: nothing more is asked of a configuration
// (ChooseConfiguration says why).
std::string BuildProblem(const Scene& scene) {
  try {
    const AsyncRegions regions(scene, AsyncRegions::kSubstepSafety);
    // A sliding tool's primary follows it on threads: a follow takes time (kThreadsFollowSlack).
    const RegionPartition& partition = regions.partition();
    if (partition.proxy_contact()) {
      CheckPrimaryReachesTip(scene, partition.mesh().options().spacing_m, kThreadsFollowSlack);
    }
    return "";
  } catch (const Error& e) {
    return e.what();
  }
}

// The query for one configuration's error at the scene's point: the input frequency and
// amplitude unknown (their worst case over the map), and the contact node anywhere within
// `reach_nodes` of the scene's along each axis (the worst case over the mapped nodes there; the
// box is clipped to the map's nodes, so that only the scene's own node outside them is clamped).
LookupQuery ConfigurationQuery(const ErrorMap& map, const MapPoint& at,
                               const RegionConfiguration& c, int reach_nodes) {
  LookupQuery query = LookupQuery::At(at);
  query.lo[kLod] = query.hi[kLod] = c.secondary_lod;
  query.lo[kSize] = query.hi[kSize] = c.primary_size;
  query.lo[kRate] = query.hi[kRate] = c.secondary_rate_hz;
  const int amplitude = static_cast<int>(MapAxis::kAmplitude);
  query.lo[amplitude] = map.axes[amplitude].front();
  query.hi[amplitude] = map.axes[amplitude].back();
  query.frequency_known = false;
  for (const MapAxis node_axis :
       {MapAxis::kContactNodeX, MapAxis::kContactNodeY, MapAxis::kContactNodeZ}) {
    const int a = static_cast<int>(node_axis);
    const double node = at[a];
    query.lo[a] = std::min(node, std::max(node - reach_nodes, map.axes[a].front()));
    query.hi[a] = std::max(node, std::min(node + reach_nodes, map.axes[a].back()));
  }
  return query;
}

}  // namespace

int LookaheadNodes(const Scene& scene) { return UsesProxyContact(scene) ? kLookaheadNodes : 0; }

RegionConfiguration AtEqualRates(const Scene& scene, RegionConfiguration configuration) {
  const double primary_hz = PrimaryRateHz(scene);
  configuration.secondary_rate_hz = primary_hz;
  // The outer rate only where shells beyond the first run at another: elsewhere the regions are
  // the same, and a configuration already at equal rates stays itself.
  if (scene.adaptivity.secondary_regions > 1 && scene.adaptivity.outer_rate_hz != primary_hz) {
    configuration.outer_rate_hz = primary_hz;
  }
  return configuration;
}

std::string DescribeConfiguration(const RegionConfiguration& c) {
  std::ostringstream text;
  text << "primary_size " << c.primary_size << ", secondary_lod " << c.secondary_lod
       << ", secondary_rate " << c.secondary_rate_hz << " Hz";
  if (c.outer_rate_hz > 0) text << ", outer_rate " << c.outer_rate_hz << " Hz";
  return text.str();
}

std::string DescribeContactNode(const LatticeIndex& node) {
  return "contact node (" + std::to_string(node[0]) + ", " + std::to_string(node[1]) + ", " +
         std::to_string(node[2]) + ")";
}

NodeError LookupErrorAt(const ErrorMap& map, const Scene& scene,
                        const RegionConfiguration& configuration, const LatticeIndex& node,
                        int reach_nodes) {
  NodeError out;
  if (!map.grid) return out;
  LookupResult result;
  try {  // a map the lookup cannot take (an axis of more than 64 values): no error, never a throw
    const ErrorLookup lookup(map, ErrorField::kMagnitude);
    result = lookup.Lookup(ConfigurationQuery(
        map, PointOfScene(SceneWith(scene, configuration, node)), configuration, reach_nodes));
  } catch (const Error&) {
    return out;
  }
  out.usable = result.usable();
  out.error_percent = result.usable() ? result.error : -1;
  out.clamped = result.clamped;
  return out;
}

Scene SceneWith(const Scene& scene, const RegionConfiguration& c) {
  Scene out = scene;
  out.adaptivity.primary_size = c.primary_size;
  out.adaptivity.secondary_lod = c.secondary_lod;
  out.adaptivity.secondary_rate_hz = c.secondary_rate_hz;
  if (c.outer_rate_hz > 0) out.adaptivity.outer_rate_hz = c.outer_rate_hz;
  return out;
}

Scene SceneWith(const Scene& scene, const RegionConfiguration& c, const LatticeIndex& node) {
  Scene out = SceneWith(scene, c);
  out.input.contact_node = node;
  return out;
}

CentredConfiguration VerifyCentredOn(const Scene& scene, const RegionConfiguration& configuration,
                                     const LatticeIndex& node) {
  const Scene centred = SceneWith(scene, configuration, node);
  ValidateScene(centred);  // a node off the surface or on a support is refused with its reason
  if (const std::string problem = BuildProblem(centred); !problem.empty()) {
    throw Error(DescribeConfiguration(configuration) + " cannot run around " +
                DescribeContactNode(node) + ": " + problem);
  }
  return {configuration, true, false};
}

std::string MapProblem(const Scene& scene, const ErrorMap& map) {
  if (!map.grid) return "";
  try {
    const ErrorLookup lookup(map, ErrorField::kMagnitude);
    const MapPoint own = PointOfScene(scene);
    for (int a = 0; a < kNumMapAxes; ++a) {
      for (double value : map.axes[a]) {
        MapPoint point = own;
        point[a] = value;
        (void)SceneAtPoint(scene, point);  // throws naming the key, for a value it refuses
      }
    }
    for (double rate : map.axes[kRate]) {
      if (rate > PrimaryRateHz(scene)) {
        return "adaptivity.secondary_rate = " + FormatReal(rate) +
               " Hz in the map is above the primary rate, " + FormatReal(PrimaryRateHz(scene)) +
               " Hz";
      }
    }
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

namespace {

struct Candidate {
  RegionConfiguration configuration;
  double error = -1, cost = 0;
  bool clamped = false;
  int reach_nodes = 0;  // the error is the worst within this many nodes of the contact node
};

// Mean measured cost of each configuration (secondary_lod, primary_size, secondary_rate) over the
// map's ok samples, µs per simulated ms.
std::map<std::array<double, 3>, double> MeanCosts(const ErrorMap& map) {
  std::map<std::array<double, 3>, std::pair<double, int>> sums;
  for (const MapSample& s : map.samples) {
    if (s.status != SampleStatus::kOk) continue;
    auto& entry = sums[{s.point[kLod], s.point[kSize], s.point[kRate]}];
    entry.first += s.total_cost_us_per_ms();
    entry.second += 1;
  }
  std::map<std::array<double, 3>, double> means;
  for (const auto& [key, sum] : sums) means[key] = sum.first / sum.second;
  return means;
}

// Every configuration of the map usable at this scene (the pinned one only, when pinned) that
// costs less than `below_cost_us_per_ms`, with its looked-up error (the worst within
// `reach_nodes` of the contact node) and measured cost.
std::vector<Candidate> MapCandidates(const Scene& scene, const ErrorMap& map,
                                     const std::optional<RegionConfiguration>& pinned,
                                     double below_cost_us_per_ms, int reach_nodes) {
  std::vector<Candidate> candidates;
  const ErrorLookup lookup(map, ErrorField::kMagnitude);
  const std::map<std::array<double, 3>, double> cost = MeanCosts(map);
  const MapPoint at = PointOfScene(scene);
  for (double lod : map.axes[kLod]) {
    for (double size : map.axes[kSize]) {
      for (double rate : map.axes[kRate]) {
        const RegionConfiguration c{static_cast<int>(size), static_cast<int>(lod), rate};
        if (pinned && !(c == *pinned)) continue;
        const LookupResult result = lookup.Lookup(ConfigurationQuery(map, at, c, reach_nodes));
        if (!result.usable()) continue;  // predicted unstable or diverged in the map
        const auto entry = cost.find({lod, size, rate});
        const double mean_cost = entry == cost.end() ? 1e9 : entry->second;
        if (!(mean_cost < below_cost_us_per_ms)) continue;
        candidates.push_back({c, result.error, mean_cost, result.clamped, reach_nodes});
      }
    }
  }
  return candidates;
}

// Why a candidate was chosen, as the log and the status say it.
std::string ReasonFor(const Candidate& candidate, bool have_map, bool target_met,
                      double target_percent) {
  std::ostringstream reason;
  reason << DescribeConfiguration(candidate.configuration);
  if (have_map) {
    reason << ": looked-up error " << candidate.error << " %";
    if (candidate.reach_nodes > 0) {
      reason << " (the worst within " << candidate.reach_nodes << " nodes of the contact node)";
    }
    reason << " against the target " << target_percent << " %"
           << (target_met ? "" : " (TARGET EXCEEDED)")
           << (candidate.clamped ? " (the scene is outside the map: clamped)" : "");
  } else {
    reason << ": no error map, the error is unknown";
  }
  return reason.str();
}

}  // namespace

SupervisorDecision ChooseConfiguration(const Scene& scene, const ErrorMap* map,
                                       double target_percent,
                                       const std::optional<RegionConfiguration>& pinned,
                                       double below_cost_us_per_ms) {
  const bool capped = below_cost_us_per_ms < std::numeric_limits<double>::infinity();
  std::vector<Candidate> candidates;
  // Only a map it can use: its lookup takes every axis and its configuration values are whole
  // numbers in range (they are cast to int).
  if (map && map->grid && MapProblem(scene, *map).empty()) {
    // A sliding tool takes the regions on across the face: judged over the nodes ahead, and
    // where nothing is usable over all of them, at the contact node alone.
    const int reach = LookaheadNodes(scene);
    candidates = MapCandidates(scene, *map, pinned, below_cost_us_per_ms, reach);
    if (candidates.empty() && reach > 0) {
      candidates = MapCandidates(scene, *map, pinned, below_cost_us_per_ms, 0);
    }
  }
  if (candidates.empty() && capped) {
    throw Error("no usable configuration in the error map is cheaper than " +
                std::to_string(below_cost_us_per_ms) + " µs per simulated ms");
  }
  if (candidates.empty()) {  // no map, or nothing usable in it: the scene's own configuration
    const RegionConfiguration own = pinned.value_or(
        RegionConfiguration{scene.adaptivity.primary_size, scene.adaptivity.secondary_lod,
                            scene.adaptivity.secondary_rate_hz});
    candidates.push_back({own, -1, 0, false});
  }
  const bool have_map = candidates.front().error >= 0;
  // Cheapest first among those meeting the target; then the most accurate of the rest.
  std::stable_sort(candidates.begin(), candidates.end(),
                   [&](const Candidate& a, const Candidate& b) {
                     const bool a_meets = a.error >= 0 && a.error <= target_percent;
                     const bool b_meets = b.error >= 0 && b.error <= target_percent;
                     if (a_meets != b_meets) return a_meets;
                     if (a_meets) return a.cost < b.cost;
                     return a.error < b.error;
                   });
  SupervisorDecision decision;
  decision.have_map = have_map;
  std::string problem;
  for (const Candidate& candidate : candidates) {
    ++decision.candidates_built;
    problem = BuildProblem(SceneWith(scene, candidate.configuration));
    if (!problem.empty()) continue;
    decision.configuration = candidate.configuration;
    decision.error_percent = candidate.error;
    decision.cost_us_per_ms = candidate.cost;
    decision.clamped = candidate.clamped;
    decision.target_met = have_map && candidate.error <= target_percent;
    decision.reason = ReasonFor(candidate, have_map, decision.target_met, target_percent);
    return decision;
  }
  throw Error(pinned ? "the pinned configuration " + DescribeConfiguration(*pinned) +
                           " cannot run on this scene: " + problem
                     : "no configuration can run on this scene (" +
                           std::to_string(decision.candidates_built) +
                           " tried; the last: " + problem + ")");
}

}  // namespace hapticsim
