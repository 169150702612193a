// Table I's partial correlations against a case with a known answer: the error is a linear
// function of two parameters plus independent noise, the parameters drawn independently.
#include "core/errormap/map_statistics.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/error.hpp"

namespace hapticsim {
namespace {

constexpr int kNu = static_cast<int>(MapAxis::kPoissonRatio);
constexpr int kE = static_cast<int>(MapAxis::kYoungsModulus);
constexpr int kRate = static_cast<int>(MapAxis::kSecondaryRate);

// error = a·ν' + b·E' + ε with ν', E' uniform on [0, 1) and ε ~ N(0, σ²), every other axis
// constant. Controlling for E, the partial correlation with ν is the correlation of a·ν' + ε
// with ν': a·s / √(a²·s² + σ²), s² = 1/12 the variance of the uniform.
ErrorMap LinearMap(std::size_t n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0, 1);
  std::normal_distribution<double> noise(0, 0.5);
  ErrorMap map;
  map.grid = false;
  for (std::size_t i = 0; i < n; ++i) {
    MapSample s;
    s.point.fill(1.0);
    const double nu = unit(rng), e = unit(rng);
    s.point[kNu] = 0.40 + 0.09 * nu;
    s.point[kE] = 5000 + 15000 * e;
    s.point[kRate] = 600 + 400 * unit(rng);  // varies, unrelated to the error
    s.status = SampleStatus::kOk;
    s.l2_percent = 2.0 * nu + 1.0 * e + noise(rng);
    s.reference_peak_n = 1.0;  // constant
    map.samples.push_back(s);
  }
  return map;
}

TEST(MapStatistics, PartialCorrelationsMatchTheKnownValueAndConstantAxesTakeNoFreedom) {
  const ErrorMap map = LinearMap(20000, 3);
  const PartialCorrelationTable table = PartialCorrelations(map, ErrorField::kL2);
  ASSERT_EQ(table.samples, 20000u);
  auto row = [&](const std::string& name) -> const PartialCorrelationRow& {
    for (const PartialCorrelationRow& r : table.rows) {
      if (r.name == name) return r;
    }
    throw std::runtime_error("no row " + name);
  };
  const double s = std::sqrt(1.0 / 12);
  const double expected_nu = 2.0 * s / std::sqrt(4.0 * s * s + 0.25);
  const double expected_e = 1.0 * s / std::sqrt(1.0 * s * s + 0.25);
  ASSERT_TRUE(row("poisson_ratio").pearson);
  EXPECT_NEAR(row("poisson_ratio").pearson->coefficient, expected_nu, 0.01);
  EXPECT_NEAR(row("youngs_modulus").pearson->coefficient, expected_e, 0.01);
  EXPECT_NEAR(row("secondary_rate").pearson->coefficient, 0.0, 0.03);  // unrelated
  EXPECT_GT(row("secondary_rate").pearson->p_value, 1e-3);
  EXPECT_FALSE(row("density").pearson);  // constant: no partial correlation
  EXPECT_FALSE(row("reference_force").pearson);
}

TEST(MapStatistics, APValueCountsOnlyTheControlsThatVary) {
  // 30 samples: the rate's p-value controls for ν and E (k = 2), not for the nine constant axes
  // as well (k = 11 would be a t distribution of 17 degrees of freedom instead of 26).
  const PartialCorrelationTable table = PartialCorrelations(LinearMap(30, 5), ErrorField::kL2);
  int rate_rows = 0;
  for (const PartialCorrelationRow& r : table.rows) {
    if (r.name != "secondary_rate") continue;
    ++rate_rows;
    ASSERT_TRUE(r.pearson);
    EXPECT_DOUBLE_EQ(r.pearson->p_value, CorrelationPValue(r.pearson->coefficient, 30, 2));
    EXPECT_GT(std::abs(r.pearson->p_value - CorrelationPValue(r.pearson->coefficient, 30, 11)),
              1e-6);
  }
  EXPECT_EQ(rate_rows, 1) << "the table has one secondary_rate row";
}

TEST(MapStatistics, TooFewSamplesForTheVaryingParametersAreRefused) {
  // Three varying parameters and the error: 3 + 3 = 6 samples needed.
  EXPECT_THROW(PartialCorrelations(LinearMap(5, 1), ErrorField::kL2), Error);
  EXPECT_NO_THROW(PartialCorrelations(LinearMap(6, 1), ErrorField::kL2));
}

}  // namespace
}  // namespace hapticsim
