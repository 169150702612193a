#include "core/errormap/error_lookup.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/error.hpp"

namespace hapticsim {
namespace {

constexpr int kNu = 0, kRho = 1, kE = 3, kFreq = 5, kSize = 7, kRate = 8;

// A grid whose l2 error is a known multilinear function of the point, so interpolation has an
// exact answer to meet.
double Truth(const MapPoint& p) {
  return 1 + 100 * p[kNu] + 2e-4 * p[kE] + 3 * p[kFreq] - 0.5 * p[kSize] + 0.01 * p[kRate] +
         0.01 * p[kNu] * p[kE] * 1e-2 - 2 * p[kFreq] * p[kNu];
}

ErrorMap SyntheticMap() {
  std::array<std::vector<double>, kNumMapAxes> axes;
  for (auto& axis : axes) axis = {1.0};
  axes[kNu] = {0.40, 0.45, 0.49};
  axes[kRho] = {800, 1200};
  axes[kE] = {5000, 10000, 20000};
  axes[kFreq] = {0.5, 1.0, 1.25};
  axes[kSize] = {1, 2, 3, 4};
  axes[kRate] = {600, 800, 1000};
  ErrorMap map = ErrorMap::MakeGrid(axes);
  for (MapSample& s : map.samples) {
    s.status = SampleStatus::kOk;
    s.l2_percent = Truth(s.point);
  }
  return map;
}

MapPoint Centre() {
  ErrorMap map = SyntheticMap();
  MapPoint p = map.samples.front().point;
  p[kNu] = 0.43;
  p[kRho] = 1000;
  p[kE] = 12000;
  p[kFreq] = 0.8;
  p[kSize] = 2;
  p[kRate] = 700;
  return p;
}

TEST(ErrorLookup, MultilinearDataIsInterpolatedExactly) {
  const ErrorLookup lookup(SyntheticMap(), ErrorField::kL2);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0, 1);
  for (int trial = 0; trial < 200; ++trial) {
    MapPoint p = Centre();
    p[kNu] = 0.40 + 0.09 * u(rng);
    p[kE] = 5000 + 15000 * u(rng);
    p[kFreq] = 0.5 + 0.75 * u(rng);
    p[kRate] = 600 + 400 * u(rng);
    p[kSize] = 1 + std::floor(4 * u(rng) - 1e-9);
    const LookupResult r = lookup.Lookup(LookupQuery::At(p));
    ASSERT_TRUE(r.usable());
    EXPECT_FALSE(r.clamped);
    EXPECT_NEAR(r.error, Truth(p), 1e-9 * std::abs(Truth(p)));
  }
}

TEST(ErrorLookup, OutsideTheMapClampsAndSaysSoNeverExtrapolates) {
  const ErrorLookup lookup(SyntheticMap(), ErrorField::kL2);
  MapPoint p = Centre();
  p[kE] = 40000;  // beyond the stiffest mapped material
  const LookupResult r = lookup.Lookup(LookupQuery::At(p));
  EXPECT_TRUE(r.clamped);
  EXPECT_EQ(r.clamped_axis, kE);
  MapPoint edge = p;
  edge[kE] = 20000;
  EXPECT_DOUBLE_EQ(r.error, Truth(edge));
  p[kE] = NAN;
  EXPECT_TRUE(lookup.Lookup(LookupQuery::At(p)).clamped);
}

// A contact node between mapped ones interpolates between them; one beyond them is the edge's
// value, flagged with the contact axis.
TEST(ErrorLookup, ContactNodesBetweenMappedOnesInterpolateAndOthersClamp) {
  constexpr int kX = static_cast<int>(MapAxis::kContactNodeX);
  constexpr int kY = static_cast<int>(MapAxis::kContactNodeY);
  std::array<std::vector<double>, kNumMapAxes> axes;
  for (auto& axis : axes) axis = {1.0};
  axes[kX] = {3, 6};
  axes[kY] = {2, 6};
  ErrorMap map = ErrorMap::MakeGrid(axes);
  for (MapSample& s : map.samples) {
    s.status = SampleStatus::kOk;
    s.max_magnitude_percent = 1 + s.point[kX] + 10 * s.point[kY];  // bilinear (here linear)
  }
  const ErrorLookup lookup(map, ErrorField::kMagnitude);
  MapPoint p = map.samples.front().point;
  p[kX] = 4, p[kY] = 5;  // a node no sweep ran
  LookupResult r = lookup.Lookup(LookupQuery::At(p));
  EXPECT_FALSE(r.clamped);
  EXPECT_NEAR(r.error, 1 + 4 + 50, 1e-12);
  p[kX] = 8;  // beyond the mapped nodes
  r = lookup.Lookup(LookupQuery::At(p));
  EXPECT_TRUE(r.clamped);
  EXPECT_EQ(r.clamped_axis, kX);
  EXPECT_NEAR(r.error, 1 + 6 + 50, 1e-12);
}

TEST(ErrorLookup, UnknownFrequencyTakesTheBoundOverTheFrequencyAxis) {
  const ErrorLookup lookup(SyntheticMap(), ErrorField::kL2);
  LookupQuery query = LookupQuery::At(Centre());
  query.frequency_known = false;
  const LookupResult r = lookup.Lookup(query);
  double worst = -INFINITY;
  for (double f : {0.5, 1.0, 1.25}) {
    MapPoint p = Centre();
    p[kFreq] = f;
    worst = std::max(worst, lookup.Lookup(LookupQuery::At(p)).error);
  }
  EXPECT_DOUBLE_EQ(r.error, worst);
  EXPECT_FALSE(r.clamped);
}

TEST(ErrorLookup, WorstCaseOverANeighbourhoodBoundsEveryPointInIt) {
  const ErrorLookup lookup(SyntheticMap(), ErrorField::kL2);
  LookupQuery query = LookupQuery::At(Centre());
  query.lo[kNu] = 0.41, query.hi[kNu] = 0.48;
  query.lo[kE] = 6000, query.hi[kE] = 15000;
  query.lo[kRho] = 900, query.hi[kRho] = 1100;
  const double worst = lookup.Lookup(query).error;
  // Brute force over a fine sampling of the box: never above the worst case, and reaching it.
  double sampled = -INFINITY;
  for (int i = 0; i <= 14; ++i) {
    for (int j = 0; j <= 18; ++j) {
      MapPoint p = Centre();
      p[kNu] = 0.41 + 0.07 * i / 14.0;
      p[kE] = 6000 + 9000 * j / 18.0;
      p[kRho] = 900;
      const double e = lookup.Lookup(LookupQuery::At(p)).error;
      EXPECT_LE(e, worst + 1e-12);
      sampled = std::max(sampled, e);
    }
  }
  EXPECT_NEAR(sampled, worst, 1e-9);
  query.neighbourhood = LookupQuery::Neighbourhood::kAverage;
  MapPoint mid = Centre();
  mid[kNu] = 0.445, mid[kE] = 10500;
  EXPECT_NEAR(lookup.Lookup(query).error, Truth(mid), 1e-9);
}

TEST(ErrorLookup, AnUnstableNeighbourGivesNoFiniteErrorButAZeroWeightOneDoesNot) {
  ErrorMap map = SyntheticMap();
  std::array<int, kNumMapAxes> index{};
  index[kNu] = 2, index[kE] = 2, index[kFreq] = 1, index[kSize] = 1, index[kRate] = 0;
  map.samples[map.GridIndex(index)].status = SampleStatus::kPredictedUnstable;
  const ErrorLookup lookup(map, ErrorField::kL2);
  MapPoint inside = Centre();  // in the cell next to the unstable corner
  inside[kNu] = 0.47, inside[kE] = 15000, inside[kFreq] = 0.9, inside[kRate] = 700;
  const LookupResult r = lookup.Lookup(LookupQuery::At(inside));
  EXPECT_TRUE(r.unstable);
  EXPECT_TRUE(std::isinf(r.error));
  MapPoint on_grid = inside;  // on the rate grid line 800: the unstable 600 Hz corner weighs 0
  on_grid[kRate] = 800;
  EXPECT_TRUE(lookup.Lookup(LookupQuery::At(on_grid)).usable());
}

TEST(ErrorLookup, AScatteredMapIsRefused) {
  ErrorMap map;
  map.grid = false;
  EXPECT_THROW(ErrorLookup(map, ErrorField::kL2), hapticsim::Error);
}

}  // namespace
}  // namespace hapticsim
