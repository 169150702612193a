// RegionIntegrator's port limits (PortWorkLimits): a port asked to do less work than it would
// does exactly the limit, to round-off, and the region's discrete energy balance still holds
// exactly; a limit it does not reach changes nothing, bit for bit; the contact is never touched.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "core/fem/region_integrator.hpp"
#include "core/regions/region_partition.hpp"
#include "tests/support/adaptive_scene.hpp"

namespace hapticsim {
namespace {

// One region of the default scene's partition (k 2 r 3, 600 Hz), from a random state, with a
// random load on its inner Γ and random prescribed values near its current ones.
class PortLimitsTest : public ::testing::Test {
 protected:
  PortLimitsTest() : partition_(testing::AdaptiveScene(3, 2, 600)) {}

  std::unique_ptr<RegionIntegrator> MakeRegion(RegionIndex a) {
    const RegionDofs& dofs = partition_.dofs(a);
    std::vector<int> prescribed;
    if (a == kPrimaryRegion) {
      prescribed.assign(partition_.contact_dofs().begin(), partition_.contact_dofs().end());
    }
    prescribed.insert(prescribed.end(), dofs.fixed.begin(), dofs.fixed.end());
    port_from_ = prescribed.size();
    prescribed.insert(prescribed.end(), dofs.outer_interface.begin(), dofs.outer_interface.end());
    auto region =
        std::make_unique<RegionIntegrator>(partition_.stiffness(a), partition_.dof_mass(), 10.0,
                                           dofs.owned, prescribed, dofs.inner_interface, 1e-3);
    region->SetPortPrescribedFrom(port_from_);
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> uniform(-1e-4, 1e-4);
    Eigen::VectorXd u = Eigen::VectorXd::Zero(partition_.mesh().num_dofs());
    Eigen::VectorXd up = u;
    for (int dof : dofs.owned) {
      u[dof] = uniform(rng);
      up[dof] = u[dof] + 0.1 * uniform(rng);
    }
    for (size_t k = port_from_; k < prescribed.size(); ++k) {
      u[prescribed[k]] = uniform(rng);
      up[prescribed[k]] = u[prescribed[k]] + 0.1 * uniform(rng);
    }
    region->SetState(u, up);
    return region;
  }

  // The step's input, drawn once: a load on the inner Γ, the contact moved 1 mm, the supports
  // held, the outer Γ moved near its current values.
  void DrawInput(RegionIndex a) {
    auto region = MakeRegion(a);
    std::mt19937_64 rng(4);
    std::uniform_real_distribution<double> uniform(-1e-4, 1e-4);
    load_.assign(region->loaded().size(), 0.0);
    for (double& f : load_) f = 100 * uniform(rng);
    next_.assign(region->prescribed().size(), 0.0);
    for (size_t k = 0; k < next_.size(); ++k) {
      if (k >= port_from_) {
        next_[k] = region->u()[region->prescribed()[k]] + uniform(rng);
      } else if (a == kPrimaryRegion && k < 3) {
        next_[k] = 1e-3;
      }
    }
  }

  // Σ over the port prescribed DOFs of their work in the last step.
  double PortWork(const RegionIntegrator& region) const {
    double work = 0;
    for (size_t k = port_from_; k < region.prescribed().size(); ++k) {
      work += region.PrescribedWork(static_cast<int>(k));
    }
    return work;
  }

  // H after − H before − (load work + prescribed work − damping − controlled): exactly 0.
  static double BalanceResidual(RegionIntegrator& region, double before) {
    double prescribed = 0;
    for (size_t k = 0; k < region.prescribed().size(); ++k) {
      prescribed += region.PrescribedWork(static_cast<int>(k));
    }
    return region.DiscreteEnergy() - before -
           (region.LoadWork() + prescribed - region.DampingDissipated() -
            region.ControlledDissipated());
  }

  RegionPartition partition_;
  size_t port_from_ = 0;
  std::vector<double> load_, next_;
};

TEST_F(PortLimitsTest, ALoadAskedToDoLessDoesExactlyTheLimitAndTheBalanceHolds) {
  DrawInput(1);
  auto free = MakeRegion(1);
  free->Step(next_, load_);
  if (free->LoadWork() < 0) {  // −f does αA − αB ≥ A − B > 0 where f did A + B < 0
    for (double& f : load_) f = -f;
    free = MakeRegion(1);
    free->Step(next_, load_);
  }
  const double unlimited = free->LoadWork();
  ASSERT_GT(unlimited, 0);
  for (double share : {0.5, 0.1, 0.0}) {
    auto region = MakeRegion(1);
    const double before = region->DiscreteEnergy();
    PortWorkLimits limits;
    limits.load_work_j = share * unlimited;
    region->Step(next_, load_, 0, limits);
    EXPECT_NEAR(region->LoadWork(), share * unlimited, 1e-12 * unlimited) << share;
    EXPECT_NEAR(region->LoadWorkRefused(), (1 - share) * unlimited, 1e-12 * unlimited) << share;
    EXPECT_NEAR(BalanceResidual(*region, before), 0, 1e-12 * before) << share;
  }
}

// A load large enough that its own push dominates its work (A ≫ |B|) does positive work either
// way round, and f and −f put B on either side of zero: both forms of the root.
TEST_F(PortLimitsTest, ALoadLimitHoldsOnBothRootBranches) {
  DrawInput(1);
  for (double& f : load_) f *= 1e3;
  for (int sign : {1, -1}) {
    for (double& f : load_) f = -f;
    auto free = MakeRegion(1);
    free->Step(next_, load_);
    const double unlimited = free->LoadWork();
    ASSERT_GT(unlimited, 0) << sign;
    auto region = MakeRegion(1);
    const double before = region->DiscreteEnergy();
    PortWorkLimits limits;
    limits.load_work_j = 0.25 * unlimited;
    region->Step(next_, load_, 0, limits);
    EXPECT_NEAR(region->LoadWork(), 0.25 * unlimited, 1e-12 * unlimited) << sign;
    EXPECT_NEAR(BalanceResidual(*region, before), 0, 1e-12 * unlimited) << sign;
  }
}

TEST_F(PortLimitsTest, ALimitNotReachedChangesNothing) {
  DrawInput(1);
  auto free = MakeRegion(1);
  free->Step(next_, load_);
  auto limited = MakeRegion(1);
  PortWorkLimits limits;
  limits.load_work_j = 2 * free->LoadWork();
  limited->Step(next_, load_, 0, limits);
  EXPECT_EQ(free->u(), limited->u());  // bit for bit
  EXPECT_EQ(limited->LoadWorkRefused(), 0);
}

TEST_F(PortLimitsTest, APrescribedLimitNotReachedChangesNothing) {
  DrawInput(kPrimaryRegion);
  auto free = MakeRegion(kPrimaryRegion);
  free->Step(next_, load_);
  auto limited = MakeRegion(kPrimaryRegion);
  PortWorkLimits limits;
  limits.prescribed_work_j = std::abs(PortWork(*free)) + 1.0;
  limited->Step(next_, load_, 0, limits);
  EXPECT_EQ(free->u(), limited->u());  // bit for bit
  EXPECT_EQ(limited->PrescribedWorkRefused(), 0);
}

TEST_F(PortLimitsTest, APrescribedPortAskedToDoLessDoesExactlyTheLimitAndTheContactStays) {
  DrawInput(kPrimaryRegion);
  auto free = MakeRegion(kPrimaryRegion);
  free->Step(next_, load_);
  double unlimited = PortWork(*free);
  if (unlimited < 0) {  // make the port's motion do positive work: reverse it about u⁻
    const Eigen::VectorXd previous = MakeRegion(kPrimaryRegion)->u_previous();
    for (size_t k = port_from_; k < next_.size(); ++k) {
      next_[k] = 2 * previous[free->prescribed()[k]] - next_[k];
    }
    free = MakeRegion(kPrimaryRegion);
    free->Step(next_, load_);
    unlimited = PortWork(*free);
  }
  ASSERT_GT(unlimited, 0);
  for (double share : {0.5, 0.0}) {
    auto region = MakeRegion(kPrimaryRegion);
    const double before = region->DiscreteEnergy();
    const Eigen::VectorXd previous = region->u_previous();
    PortWorkLimits limits;
    limits.prescribed_work_j = share * unlimited;
    region->Step(next_, load_, 0, limits);
    EXPECT_NEAR(PortWork(*region), share * unlimited, 1e-12 * unlimited) << share;
    EXPECT_NEAR(region->PrescribedWorkRefused(), (1 - share) * unlimited, 1e-12 * unlimited);
    EXPECT_NEAR(BalanceResidual(*region, before), 0, 1e-12 * before) << share;
    for (size_t k = 0; k < 3; ++k) EXPECT_EQ(region->u()[region->prescribed()[k]], next_[k]);
    // Scaled towards u⁻, never past the motion it was sent.
    for (size_t k = port_from_; k < next_.size(); ++k) {
      const int dof = region->prescribed()[k];
      EXPECT_LE(std::abs(region->u()[dof] - previous[dof]),
                std::abs(next_[k] - previous[dof]) * (1 + 1e-12));
    }
  }
}

}  // namespace
}  // namespace hapticsim
