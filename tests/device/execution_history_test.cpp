// The device's summary of the daemon threads' step times, from status messages as the daemon
// sends them.
#include "device/execution_history.hpp"

#include <gtest/gtest.h>

namespace hapticsim::device {
namespace {

status_t StatusOf(const std::vector<std::array<double, 3>>& p50_p99_max_us) {
  status_t s{};
  const char* names[] = {"primary", "secondary"};
  const double rates[] = {1000, 600};
  for (size_t r = 0; r < p50_p99_max_us.size(); ++r) {
    region_status_t region{};
    region.name = names[r];
    region.rate_hz = rates[r];
    region.execution_p50_us = p50_p99_max_us[r][0];
    region.execution_p99_us = p50_p99_max_us[r][1];
    region.execution_max_us = p50_p99_max_us[r][2];
    s.regions.push_back(region);
  }
  s.num_regions = static_cast<std::int32_t>(s.regions.size());
  return s;
}

TEST(ExecutionHistory, TheMedianOfTheIntervalsMediansTheWorstP99AndTheLongestStep) {
  ExecutionHistory history;
  history.Add(StatusOf({{35.5, 44.4, 50}, {69.4, 86.7, 90}}));
  history.Add(StatusOf({{44.4, 135.5, 1066}, {69.4, 69.4, 70}}));
  history.Add(StatusOf({{35.5, 55.5, 60}, {0, 0, 0}}));  // the secondary asleep: not counted
  const auto summary = history.Summary();
  ASSERT_EQ(summary.size(), 2u);
  EXPECT_EQ(summary[0].region, "primary");
  EXPECT_EQ(summary[0].intervals, 3);
  EXPECT_DOUBLE_EQ(summary[0].p50_median_us, 35.5);  // of 35.5, 44.4, 35.5
  EXPECT_DOUBLE_EQ(summary[0].p99_median_us, 55.5);  // of 44.4, 135.5, 55.5
  EXPECT_DOUBLE_EQ(summary[0].p99_worst_us, 135.5);
  EXPECT_DOUBLE_EQ(summary[0].max_us, 1066);
  EXPECT_NEAR(summary[0].p50_period_share(), 0.0355, 1e-12);  // of 1 ms
  EXPECT_EQ(summary[1].region, "secondary");
  EXPECT_EQ(summary[1].intervals, 2);
  EXPECT_DOUBLE_EQ(summary[1].p50_median_us, 69.4);
  EXPECT_DOUBLE_EQ(summary[1].p99_worst_us, 86.7);
  EXPECT_NEAR(summary[1].p50_period_share(), 69.4e-6 * 600, 1e-12);
}

TEST(ExecutionHistory, NothingBeforeTheFirstStatusThatStepped) {
  ExecutionHistory history;
  EXPECT_TRUE(history.Summary().empty());
  history.Add(StatusOf({{0, 0, 0}}));  // asleep at rest from the start
  EXPECT_TRUE(history.Summary().empty());
}

}  // namespace
}  // namespace hapticsim::device
