#pragma once

#include <Eigen/Core>
#include <random>

namespace hapticsim::testing {

/** A reproducible vector of uniform values in [−scale, scale]. */
inline Eigen::VectorXd RandomField(Eigen::Index size, unsigned seed, double scale = 1.0) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uniform(-scale, scale);
  Eigen::VectorXd v(size);
  for (Eigen::Index i = 0; i < size; ++i) v[i] = uniform(rng);
  return v;
}

}  // namespace hapticsim::testing
