#pragma once

#include <vector>

namespace hapticsim {

/** One candidate of a trade-off: what it costs and how wrong it is; unusable ones take no part. */
struct TradeOff {
  double cost = 0;
  double error = 0;
  bool usable = true;
};

/**
 * The Pareto front of a cost/error trade-off: the cheapest candidate for each error level. Returns
 * indices into `candidates`, cheapest first; each has an error lower by more than
 * `error_resolution` than every cheaper one on the front, and every usable candidate not on it
 * costs at least as much as one on the front whose error is at most `error_resolution` higher
 * (with 0: no higher). Ties in cost go to the lower error, then the lower index.
 *
 * `error_resolution` keeps a configuration that costs twice as much for 10⁻⁶ % less error off
 * the front: errors closer than that are one level.
 */
std::vector<int> ParetoFront(const std::vector<TradeOff>& candidates, double error_resolution = 0);

}  // namespace hapticsim
