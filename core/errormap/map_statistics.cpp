#include "core/errormap/map_statistics.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <boost/math/distributions/students_t.hpp>
#include <cmath>
#include <numeric>

#include "core/error.hpp"

namespace hapticsim {
namespace {

// Residual of y after least squares on the columns of X (which include the constant).
Eigen::VectorXd Residual(const Eigen::MatrixXd& X, const Eigen::VectorXd& y) {
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(X);
  return y - X * qr.solve(y);
}

bool Varies(const Eigen::VectorXd& column) {
  return column.size() > 0 && column.maxCoeff() > column.minCoeff();
}

std::optional<Correlation> Partial(const Eigen::MatrixXd& variables, int target, int error_column) {
  const Eigen::Index n = variables.rows();
  // Controls: every variable but the target and the error that varies in this map (a constant
  // one is the intercept again, and would only take a degree of freedom from the p-value).
  std::vector<Eigen::Index> controls;
  for (Eigen::Index c = 0; c < variables.cols(); ++c) {
    if (c != target && c != error_column && Varies(variables.col(c))) controls.push_back(c);
  }
  const auto others = static_cast<Eigen::Index>(controls.size());
  Eigen::MatrixXd X(n, others + 1);
  X.col(0).setOnes();
  for (Eigen::Index k = 0; k < others; ++k) X.col(k + 1) = variables.col(controls[k]);
  const Eigen::VectorXd rx = Residual(X, variables.col(target));
  const Eigen::VectorXd ry = Residual(X, variables.col(error_column));
  const double sxx = rx.squaredNorm(), syy = ry.squaredNorm();
  // A parameter fully explained by the others (constant, or a function of them) has no
  // partial correlation to speak of.
  if (!(sxx > 1e-20 * variables.col(target).squaredNorm()) || !(syy > 0)) return std::nullopt;
  Correlation c;
  c.coefficient = std::clamp(rx.dot(ry) / std::sqrt(sxx * syy), -1.0, 1.0);
  c.p_value = CorrelationPValue(c.coefficient, static_cast<size_t>(n), static_cast<size_t>(others));
  return c;
}

}  // namespace

double CorrelationPValue(double r, std::size_t n, std::size_t k) {
  const double dof = static_cast<double>(n) - 2.0 - static_cast<double>(k);
  if (!(dof >= 1)) return 1.0;
  if (std::abs(r) >= 1.0) return 0.0;
  const double t = r * std::sqrt(dof / (1.0 - r * r));
  const boost::math::students_t distribution(dof);
  return 2.0 * boost::math::cdf(boost::math::complement(distribution, std::abs(t)));
}

std::vector<double> AverageRanks(const std::vector<double>& values) {
  std::vector<size_t> order(values.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return values[a] < values[b]; });
  std::vector<double> ranks(values.size());
  for (size_t i = 0; i < order.size();) {
    size_t j = i;
    while (j + 1 < order.size() && values[order[j + 1]] == values[order[i]]) ++j;
    const double rank = 0.5 * static_cast<double>(i + j) + 1.0;
    for (size_t k = i; k <= j; ++k) ranks[order[k]] = rank;
    i = j + 1;
  }
  return ranks;
}

PartialCorrelationTable PartialCorrelations(const ErrorMap& map, ErrorField field) {
  PartialCorrelationTable table;
  table.field = field;
  std::vector<const MapSample*> ok;
  for (const MapSample& s : map.samples) {
    if (s.status == SampleStatus::kOk && std::isfinite(FieldOf(s, field))) ok.push_back(&s);
  }
  constexpr int kVariables = kNumMapAxes + 1;  // the parameters and the reference force
  const int error_column = kVariables;
  table.samples = ok.size();
  const auto n = static_cast<Eigen::Index>(ok.size());
  Eigen::MatrixXd values(n, kVariables + 1);
  for (Eigen::Index i = 0; i < n; ++i) {
    for (int a = 0; a < kNumMapAxes; ++a) values(i, a) = ok[i]->point[a];
    values(i, kNumMapAxes) = ok[i]->reference_peak_n;
    values(i, error_column) = FieldOf(*ok[i], field);
  }
  int varying = 0;
  for (int c = 0; c < kVariables; ++c) varying += Varies(values.col(c)) ? 1 : 0;
  HAPTICSIM_THROW_UNLESS(ok.size() >= static_cast<size_t>(varying + 3),
                         "partial correlations need at least " + std::to_string(varying + 3) +
                             " ok samples (the varying parameters + 3); the map has " +
                             std::to_string(ok.size()));
  Eigen::MatrixXd ranks(n, kVariables + 1);
  for (int c = 0; c <= kVariables; ++c) {
    const std::vector<double> column(values.col(c).data(), values.col(c).data() + n);
    const std::vector<double> r = AverageRanks(column);
    ranks.col(c) = Eigen::Map<const Eigen::VectorXd>(r.data(), n);
  }
  for (int c = 0; c < kVariables; ++c) {
    PartialCorrelationRow row;
    row.name = c < kNumMapAxes ? std::string(AxisInfo(c).name) : "reference_force";
    row.pearson = Partial(values, c, error_column);
    row.spearman = Partial(ranks, c, error_column);
    table.rows.push_back(row);
  }
  return table;
}

}  // namespace hapticsim
