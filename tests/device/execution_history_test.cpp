// The device's summary of the daemon threads' compute time per period, from status messages as
// the daemon sends them.
#include "device/execution_history.hpp"

#include <gtest/gtest.h>

namespace hapticsim::device {
namespace {

struct Interval {
  double rate_hz, p50_us, p99_us, max_us;
};

status_t StatusOf(const std::vector<Interval>& regions, bool asleep = false) {
  status_t s{};
  const char* names[] = {"primary", "secondary"};
  for (size_t r = 0; r < regions.size(); ++r) {
    region_status_t region{};
    region.name = names[r];
    region.rate_hz = regions[r].rate_hz;
    region.execution_p50_us = regions[r].p50_us;
    region.execution_p99_us = regions[r].p99_us;
    region.execution_max_us = regions[r].max_us;
    s.regions.push_back(region);
  }
  s.num_regions = static_cast<std::int32_t>(s.regions.size());
  s.asleep = asleep;
  return s;
}

// Values chosen so that the last status, the upper median and the first or newest rate each give
// another answer than the one asked for.
TEST(ExecutionHistory, MediansOfTheIntervalsTheWorstP99AndTheLongestPeriod) {
  ExecutionHistory history;
  history.Add(StatusOf({{1000, 44.4, 55.5, 60}, {600, 69.4, 86.7, 90}}));
  history.Add(StatusOf({{1000, 35.5, 135.5, 1066}, {600, 86.7, 108.4, 120}}));
  // Asleep: the primary answers without stepping; the status says nothing about a step's cost.
  history.Add(StatusOf({{1000, 5.0, 6.0, 8}, {600, 0, 0, 0}}, /*asleep=*/true));
  // Reconfigured: the secondary now at 1000 Hz.
  history.Add(StatusOf({{1000, 86.7, 60, 110}, {1000, 44.4, 55.5, 70}}));
  history.Add(StatusOf({{1000, 55.5, 120, 130}, {1000, 35.5, 44.4, 50}}));
  const auto summary = history.Summary();
  ASSERT_EQ(summary.size(), 2u);

  const RegionExecution& primary = summary[0];
  EXPECT_EQ(primary.region, "primary");
  EXPECT_EQ(primary.intervals, 4) << "the asleep status is not counted";
  EXPECT_DOUBLE_EQ(primary.p50_median_us, 44.4);         // 35.5 44.4 | 55.5 86.7: the lower median
  EXPECT_DOUBLE_EQ(primary.p99_interval_median_us, 60);  // 55.5 60 | 120 135.5
  EXPECT_DOUBLE_EQ(primary.p99_interval_worst_us, 135.5);
  EXPECT_DOUBLE_EQ(primary.max_us, 1066);
  EXPECT_NEAR(primary.p50_period_share, 0.0444, 1e-12);

  const RegionExecution& secondary = summary[1];
  EXPECT_EQ(secondary.region, "secondary");
  EXPECT_EQ(secondary.intervals, 4);
  EXPECT_DOUBLE_EQ(secondary.rate_hz, 1000);        // the newest
  EXPECT_DOUBLE_EQ(secondary.p50_median_us, 44.4);  // 35.5 44.4 | 69.4 86.7
  // Each interval's share of its own period: 0.0355 0.04164 | 0.0444 0.05202.
  EXPECT_NEAR(secondary.p50_period_share, 69.4e-6 * 600, 1e-12);
  EXPECT_DOUBLE_EQ(secondary.p99_interval_median_us, 55.5);  // 44.4 55.5 | 86.7 108.4
  EXPECT_DOUBLE_EQ(secondary.p99_interval_worst_us, 108.4);
  EXPECT_DOUBLE_EQ(secondary.max_us, 120);
}

TEST(ExecutionHistory, NothingBeforeTheFirstStatusThatStepped) {
  ExecutionHistory history;
  EXPECT_TRUE(history.Summary().empty());
  history.Add(StatusOf({{1000, 5.0, 6.0, 8}}, /*asleep=*/true));  // asleep from the start
  history.Add(StatusOf({{1000, 0, 0, 0}}));                       // not running yet
  EXPECT_TRUE(history.Summary().empty());
}

}  // namespace
}  // namespace hapticsim::device
