#include "core/errormap/pareto_front.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace hapticsim {

std::vector<int> ParetoFront(const std::vector<TradeOff>& candidates, double error_resolution) {
  std::vector<int> order;
  for (int i = 0; i < static_cast<int>(candidates.size()); ++i) {
    const TradeOff& c = candidates[static_cast<size_t>(i)];
    if (c.usable && std::isfinite(c.cost) && std::isfinite(c.error)) order.push_back(i);
  }
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    const TradeOff &x = candidates[static_cast<size_t>(a)], &y = candidates[static_cast<size_t>(b)];
    if (x.cost != y.cost) return x.cost < y.cost;
    if (x.error != y.error) return x.error < y.error;
    return a < b;
  });
  // Walking from the cheapest: a candidate joins the front when it is more accurate than
  // everything cheaper, by more than the resolution.
  std::vector<int> front;
  for (int i : order) {
    if (front.empty() ||
        candidates[static_cast<size_t>(i)].error <
            candidates[static_cast<size_t>(front.back())].error - error_resolution) {
      front.push_back(i);
    }
  }
  return front;
}

}  // namespace hapticsim
