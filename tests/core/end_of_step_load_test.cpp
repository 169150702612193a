// RegionIntegrator's load taken at the step's end (EndOfStepLoad, the proxy's spring): the step
// satisfies central difference's equation of motion with the load the rule gave from the step's
// own end, the discrete energy balance holds with that load's work, and a stiff one-sided spring
// so taken never feeds the light nodes it pushes, where the same spring taken at the step's start
// rings them up.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <span>
#include <vector>

#include "core/fem/region_integrator.hpp"
#include "core/regions/region_partition.hpp"
#include "tests/support/adaptive_scene.hpp"
#include "tests/support/random_field.hpp"

namespace hapticsim {
namespace {

// A spring from each loaded DOF to rest, one-sided along the DOF (it only pushes towards −u,
// from u > 0: a tool face at rest), of stiffness k: −k·max(0, u⁺) at the step's end, solved
// from u⁺ = ũ + c·f.
class SpringToRest final : public EndOfStepLoad {
 public:
  explicit SpringToRest(double k) : k_(k) {}
  void Load(const Eigen::VectorXd& predicted, std::span<const double> compliance,
            std::span<double> load) noexcept override {
    for (std::size_t i = 0; i < load.size(); ++i) {
      const double free = predicted[dofs_[i]];
      load[i] = free > 0 ? -k_ * free / (1.0 + k_ * compliance[i]) : 0.0;
    }
  }
  std::vector<int> dofs_;

 private:
  double k_;
};

// The secondary region of the default scene's partition (k 2 r 3, 600 Hz), undamped, its inner Γ
// loaded, from a random state.
class EndOfStepLoadTest : public ::testing::Test {
 protected:
  EndOfStepLoadTest() : partition_(testing::AdaptiveScene(3, 2, 600)) {}

  // `slack`: at rest, but for the loaded DOFs moving towards u > 0 (1 µm a step), where
  // SpringToRest pushes.
  std::unique_ptr<RegionIntegrator> MakeRegion(double damping_per_s, double substep_s,
                                               bool slack = false) {
    const RegionDofs& dofs = partition_.dofs(1);
    std::vector<int> prescribed = dofs.fixed;
    prescribed.insert(prescribed.end(), dofs.outer_interface.begin(), dofs.outer_interface.end());
    auto region = std::make_unique<RegionIntegrator>(partition_.stiffness(1), partition_.dof_mass(),
                                                     damping_per_s, dofs.owned, prescribed,
                                                     dofs.inner_interface, substep_s);
    const Eigen::Index n = partition_.mesh().num_dofs();
    const Eigen::VectorXd at = testing::RandomField(n, 5, 1e-4),
                          moved = testing::RandomField(n, 6, 1e-5);
    Eigen::VectorXd u = Eigen::VectorXd::Zero(n), up = u;
    for (int dof : dofs.owned) u[dof] = at[dof], up[dof] = at[dof] + moved[dof];
    if (slack) {
      u.setZero();
      up.setZero();
      for (int dof : dofs.inner_interface) up[dof] = -1e-6;
    }
    region->SetState(u, up);
    held_.assign(prescribed.size(), 0.0);
    return region;
  }

  RegionPartition partition_;
  std::vector<double> held_;
};

TEST_F(EndOfStepLoadTest, TheStepMeetsItsEquationOfMotionWithTheLoadAtItsEnd) {
  constexpr double h = 2e-4, d = 10.0, k = 5000.0;
  auto region = MakeRegion(d, h);
  SpringToRest spring(k);
  spring.dofs_ = region->loaded();
  const Eigen::VectorXd u = region->u(), up = region->u_previous();
  const Eigen::VectorXd ku = region->Forces();
  const double before = region->DiscreteEnergy();
  region->Step(held_, spring);
  const Eigen::VectorXd& next = region->u();
  const Eigen::VectorXd& m = partition_.dof_mass();
  int pushed = 0;
  double prescribed_work = 0;
  for (std::size_t k_ = 0; k_ < region->prescribed().size(); ++k_)
    prescribed_work += region->PrescribedWork(static_cast<int>(k_));
  double load_work = 0;
  for (int i : region->loaded()) {
    // The load the step applied is the spring at its own end: −k·max(0, u⁺).
    const double load = next[i] > 0 ? -k * next[i] : 0.0;
    pushed += next[i] > 0 ? 1 : 0;
    const double residual = m[i] * (next[i] - 2 * u[i] + up[i]) / (h * h) +
                            d * m[i] * (next[i] - up[i]) / (2 * h) + ku[i] - load;
    EXPECT_NEAR(residual, 0.0, 1e-9 * (std::abs(ku[i]) + std::abs(load) + 1e-6)) << "DOF " << i;
    load_work += load * (next[i] - up[i]) / 2;
  }
  EXPECT_GT(pushed, 10);  // the spring took part
  EXPECT_NEAR(region->LoadWork(), load_work, 1e-12 * std::abs(load_work) + 1e-18);
  const double residual = region->DiscreteEnergy() - before -
                          (region->LoadWork() + prescribed_work - region->DampingDissipated());
  EXPECT_NEAR(residual, 0.0, 1e-9 * std::abs(before));
}

// Undamped, the region's nodes on its inner Γ, slack at the start, bounce against a spring far
// stiffer than the region's step allows explicitly (k·h²/m ≫ 4 on them). Taken at the step's end
// the spring gives back at most what it was given: the state's energy and the spring's together
// never rise above the start's. Taken at the step's start (the load from u, the old way), it
// rings the nodes up.
TEST_F(EndOfStepLoadTest, AStiffOneSidedSpringAtTheStepsEndNeverFeedsTheNodesItPushes) {
  constexpr double h = 2e-4, k = 1e8;  // k·h²/m about 400 on those nodes
  auto end = MakeRegion(0.0, h, /*slack=*/true);
  SpringToRest spring(k);
  spring.dofs_ = end->loaded();
  const auto with_spring = [&](RegionIntegrator& region) {
    double stored = region.StateEnergy();
    for (int dof : region.loaded()) stored += 0.5 * k * std::pow(std::max(0.0, region.u()[dof]), 2);
    return stored;
  };
  const double start_energy = with_spring(*end);
  double most = start_energy;
  int pushed_steps = 0;
  for (int n = 0; n < 2000; ++n) {
    end->Step(held_, spring);
    most = std::max(most, with_spring(*end));
    pushed_steps += end->LoadWork() != 0 ? 1 : 0;
  }
  EXPECT_GT(pushed_steps, 100);
  EXPECT_LE(most, 1.01 * start_energy);

  auto start = MakeRegion(0.0, h, /*slack=*/true);
  std::vector<double> load(start->loaded().size());
  double start_most = 0;
  for (int n = 0; n < 2000 && std::isfinite(start_most); ++n) {
    for (std::size_t i = 0; i < load.size(); ++i) {
      const double u = start->u()[start->loaded()[i]];
      load[i] = u > 0 ? -k * u : 0.0;
    }
    start->Step(held_, load);
    start_most = std::max(start_most, start->StateEnergy());
  }
  std::printf(
      "state energy: %.3e J at the start; at most %.3e J with the spring at the step's end, "
      "%.3e J at its start\n",
      start_energy, most, start_most);
  EXPECT_GT(start_most, 100 * start_energy);
}

}  // namespace
}  // namespace hapticsim
