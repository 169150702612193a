// The Pareto front of a cost/error trade-off, against the definition checked pair by pair.
#include "core/errormap/pareto_front.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

namespace hapticsim {
namespace {

// i is on the front when no other usable candidate is at least as cheap and at least as accurate
// and better in one of them (or the same in both and listed first).
bool Dominated(const std::vector<TradeOff>& c, size_t i) {
  for (size_t j = 0; j < c.size(); ++j) {
    if (j == i || !c[j].usable) continue;
    const bool no_worse = c[j].cost <= c[i].cost && c[j].error <= c[i].error;
    const bool better = c[j].cost < c[i].cost || c[j].error < c[i].error;
    if (no_worse && (better || j < i)) return true;
  }
  return false;
}

TEST(ParetoFront, IsExactlyTheUndominatedCandidatesCheapestFirst) {
  std::mt19937 random(3);
  // Small integer costs and errors: plenty of ties in either.
  std::uniform_int_distribution<int> value(0, 12), coin(0, 4);
  for (int trial = 0; trial < 300; ++trial) {
    std::vector<TradeOff> candidates(static_cast<size_t>(value(random) + 1));
    for (TradeOff& c : candidates) {
      c = {static_cast<double>(value(random)), static_cast<double>(value(random)),
           coin(random) != 0};
    }
    const std::vector<int> front = ParetoFront(candidates);
    std::vector<int> expected;
    for (size_t i = 0; i < candidates.size(); ++i) {
      if (candidates[i].usable && !Dominated(candidates, i))
        expected.push_back(static_cast<int>(i));
    }
    std::vector<int> sorted = front;
    std::sort(sorted.begin(), sorted.end());
    ASSERT_EQ(sorted, expected) << "trial " << trial;
    for (size_t k = 1; k < front.size(); ++k) {
      const TradeOff &cheaper = candidates[static_cast<size_t>(front[k - 1])],
                     &next = candidates[static_cast<size_t>(front[k])];
      EXPECT_LT(cheaper.cost, next.cost);
      EXPECT_GT(cheaper.error, next.error);
    }
  }
}

TEST(ParetoFront, LeavesOutUnusableAndNonFiniteCandidates) {
  const std::vector<TradeOff> candidates{
      {1, 50, true}, {0.5, 1, false}, {2, NAN, true}, {INFINITY, 0, true}, {3, 10, true}};
  EXPECT_EQ(ParetoFront(candidates), (std::vector<int>{0, 4}));
  EXPECT_TRUE(ParetoFront({}).empty());
}

TEST(ParetoFront, ErrorsCloserThanTheResolutionAreOneLevel) {
  const std::vector<TradeOff> candidates{{1, 5.0}, {2, 4.999}, {3, 4.0}, {4, 3.995}, {5, 1.0}};
  EXPECT_EQ(ParetoFront(candidates), (std::vector<int>{0, 1, 2, 3, 4}));
  EXPECT_EQ(ParetoFront(candidates, 0.01), (std::vector<int>{0, 2, 4}));
}

}  // namespace
}  // namespace hapticsim
