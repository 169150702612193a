#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/errormap/error_map.hpp"

namespace hapticsim {

/** A correlation coefficient and its two-sided p-value (t test, H0: no correlation). */
struct Correlation {
  double coefficient = 0;
  double p_value = 1;
};

/** One row of the paper's Table I: a parameter's partial correlation with the error. */
struct PartialCorrelationRow {
  std::string name;  ///< the axis name ("poisson_ratio", …) or "reference_force"
  std::optional<Correlation> pearson;   ///< none when the parameter is constant in the map
  std::optional<Correlation> spearman;  ///< the same on ranks (average ranks for ties)
};

struct PartialCorrelationTable {
  ErrorField field = ErrorField::kL2;
  std::size_t samples = 0;  ///< ok samples used (predicted unstable and diverged are left out)
  std::vector<PartialCorrelationRow> rows;
};

/**
 * Table I of the paper: the partial correlation of the error with each map parameter and the
 * reference force, each controlling for all the others that vary in the map (the error and the
 * parameter are both regressed on them; the residuals are correlated). p-values from Student's t
 * with n − 2 − k degrees of freedom (k controlled variables), two-sided.
 * @throws Error when fewer ok samples than varying variables + 3 are available.
 */
PartialCorrelationTable PartialCorrelations(const ErrorMap& map, ErrorField field);

/** Two-sided p-value of a correlation r from n samples with k controlled variables. */
double CorrelationPValue(double r, std::size_t n, std::size_t k);

/** Ranks 1…n, ties sharing their average rank. */
std::vector<double> AverageRanks(const std::vector<double>& values);

}  // namespace hapticsim
