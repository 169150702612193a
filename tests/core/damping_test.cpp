// Mass-proportional damping per material (C = Σ_e d_e·M_e, diagonal with the lumped mass: each
// DOF damps at its own rate d_i = c_i/m_i, ElasticModel::dof_damping), checked against what does
// not depend on the implementation: a freely vibrating bar of one material loses its energy as
// exp(−d·t) (every mode's amplitude decays as exp(−d·t/2)); of two materials the rate lies
// between theirs (the energy's loss rate Σ c_i v_i² lies between d₁ and d₂ times 2·kinetic);
// two labels of one material are the one material, bit for bit; and the region step's discrete
// energy balance holds exactly whatever the rates.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <random>
#include <utility>
#include <vector>

#include "core/error.hpp"
#include "core/fem/central_difference_integrator.hpp"
#include "core/fem/elastic_model.hpp"
#include "core/fem/material_field.hpp"
#include "core/fem/region_integrator.hpp"
#include "core/fem/stability_estimate.hpp"
#include "core/fem/stencil_stiffness.hpp"
#include "tests/support/random_field.hpp"

namespace hapticsim {
namespace {

// A bar 8 × 2 × 2 elements of 2 cm, held at its x = 0 face. Stiff enough (1 MPa) that its
// lowest mode (≈ 50 rad/s) is well underdamped at the rates below.
const HexGrid kBar(9, 3, 3, 0.02);

Material Damped(double d) {
  Material m;
  m.youngs_modulus_pa = 1e6;
  m.poisson_ratio = 0.3;
  m.density_kg_m3 = 1000;
  m.damping_per_s = d;
  return m;
}

// Label 0 on the half x < 4 elements, label 1 on the other half.
MaterialField Halves(const Material& near, const Material& far) {
  std::vector<std::int16_t> elements(static_cast<size_t>(kBar.num_elements()));
  for (int e = 0; e < kBar.num_elements(); ++e) {
    elements[static_cast<size_t>(e)] = (e % (kBar.nx() - 1)) < 4 ? 0 : 1;
  }
  return MaterialField(kBar, {near, far}, std::move(elements));
}

DofConstraints HeldAtXZero() {
  DofConstraints held;
  for (int iz = 0; iz < kBar.nz(); ++iz) {
    for (int iy = 0; iy < kBar.ny(); ++iy) {
      for (int c = 0; c < 3; ++c) held.fixed_dofs.push_back(kBar.Dof(kBar.Node(0, iy, iz), c));
    }
  }
  return held;
}

std::vector<int> FreeDofs(const ElasticModel& model) {
  std::vector<int> free;
  for (int dof = 0; dof < kBar.num_dofs(); ++dof) {
    if (model.free_mask()[dof] > 0) free.push_back(dof);
  }
  return free;
}

std::unique_ptr<RegionIntegrator> WholeBar(const ElasticModel& model, double dt,
                                           std::vector<int> loaded = {}) {
  auto region = std::make_unique<RegionIntegrator>(model.stiffness(), model.dof_mass(),
                                                   model.dof_damping(), FreeDofs(model),
                                                   model.constraints().fixed_dofs,
                                                   std::move(loaded), dt);
  const Eigen::VectorXd u0 =
      testing::RandomField(kBar.num_dofs(), 7, 1e-4).cwiseProduct(model.free_mask());
  region->SetState(u0, u0);  // released from rest
  return region;
}

double StableStep(const ElasticModel& model) {
  return 0.5 * EstimateStability(model).critical_dt_s;
}

// −slope of the least-squares line through ln E(t) over `seconds` of free vibration, 1/s.
double EnergyDecayRate(const ElasticModel& model, double dt, double seconds) {
  auto region = WholeBar(model, dt);
  const std::vector<double> held(model.constraints().fixed_dofs.size(), 0.0);
  const int steps = static_cast<int>(seconds / dt);
  double st = 0, sy = 0, stt = 0, sty = 0;
  for (int n = 0; n < steps; ++n) {
    region->Step(held, {});
    const double t = (n + 1) * dt, y = std::log(region->StateEnergy());
    st += t, sy += y, stt += t * t, sty += t * y;
  }
  return -(steps * sty - st * sy) / (steps * stt - st * st);
}

TEST(Damping, OneMaterialsEnergyDecaysAsExpMinusDT) {
  for (double d : {2.0, 6.0}) {
    const ElasticModel model(kBar, MaterialField(kBar, Damped(d)), HeldAtXZero());
    const double dt = StableStep(model);
    // Central difference's exact per-step factor of every mode's energy, (1 − dh/2)/(1 + dh/2).
    const double discrete = -std::log((1 - d * dt / 2) / (1 + d * dt / 2)) / dt;
    const double rate = EnergyDecayRate(model, dt, 3.0 / d);
    std::printf("d %.1f 1/s: energy decay rate %.4f 1/s (discrete d %.6f, dt %.3g s)\n", d, rate,
                discrete, dt);
    EXPECT_NEAR(rate, discrete, 0.03 * d);
  }
}

TEST(Damping, TwoMaterialsDecayBetweenTheirRates) {
  const double d1 = 2, d2 = 6;
  const ElasticModel model(kBar, Halves(Damped(d1), Damped(d2)), HeldAtXZero());
  EXPECT_FALSE(model.uniform_damping());
  const double dt = StableStep(model);
  const double rate = EnergyDecayRate(model, dt, 3.0 / d1);
  std::printf("halves d %.0f and %.0f 1/s: energy decay rate %.4f 1/s\n", d1, d2, rate);
  EXPECT_GT(rate, d1 * 1.05);
  EXPECT_LT(rate, d2 * 0.95);
  // A node between the two takes the mass-weighted rate: with equal densities, the mean of the
  // rates of its elements.
  const int between = kBar.Dof(kBar.Node(4, 1, 1), 0);  // 4 elements of each
  EXPECT_DOUBLE_EQ(model.dof_damping()[between], (d1 + d2) / 2);
  EXPECT_EQ(model.dof_damping()[kBar.Dof(kBar.Node(1, 1, 1), 2)], d1);
  EXPECT_EQ(model.dof_damping()[kBar.Dof(kBar.Node(8, 1, 1), 1)], d2);
  EXPECT_THROW(model.damping_per_s(), Error);
}

// Two labels of the same material are that material: the same mass and rate per DOF, to the
// bit, and so the same run as the one rate given to the step directly (on the same K: two labels
// take the element-by-element operator, one the stencil, which round differently).
TEST(Damping, TwoLabelsOfOneMaterialAreThatMaterialBitForBit) {
  const Material m2 = Damped(6);
  const ElasticModel one(kBar, MaterialField(kBar, m2), HeldAtXZero());
  const ElasticModel two(kBar, Halves(m2, m2), HeldAtXZero());
  ASSERT_NE(dynamic_cast<const StencilStiffness*>(&one.stiffness()), nullptr);
  ASSERT_EQ(dynamic_cast<const StencilStiffness*>(&two.stiffness()), nullptr);
  EXPECT_TRUE(two.uniform_damping());
  EXPECT_EQ(two.damping_per_s(), m2.damping_per_s);
  EXPECT_EQ(two.dof_mass(), one.dof_mass());
  EXPECT_EQ(two.dof_damping(), one.dof_damping());
  EXPECT_EQ(one.dof_damping(), Eigen::VectorXd::Constant(kBar.num_dofs(), m2.damping_per_s));

  const double dt = StableStep(one);
  auto per_dof = WholeBar(two, dt);
  RegionIntegrator one_rate(two.stiffness(), one.dof_mass(), one.damping_per_s(),
                            FreeDofs(one), one.constraints().fixed_dofs, {}, dt);
  one_rate.SetState(per_dof->u(), per_dof->u_previous());
  const std::vector<double> held(one.constraints().fixed_dofs.size(), 0.0);
  for (int n = 0; n < 2000; ++n) {
    per_dof->Step(held, {});
    one_rate.Step(held, {});
  }
  EXPECT_EQ(per_dof->u(), one_rate.u());
  EXPECT_EQ(per_dof->DampingDissipated(), one_rate.DampingDissipated());
  for (int k = 0; k < static_cast<int>(held.size()); ++k) {
    EXPECT_EQ(per_dof->PrescribedReaction(k), one_rate.PrescribedReaction(k));
  }
  // And the stencil run of the one material agrees to the stencil's round-off.
  CentralDifferenceIntegrator stencil(one, dt);
  stencil.SetState(WholeBar(one, dt)->u(), WholeBar(one, dt)->u());
  auto elementwise = WholeBar(two, dt);
  for (int n = 0; n < 2000; ++n) {
    ASSERT_EQ(stencil.Step({}), StepStatus::kOk);
    elementwise->Step(held, {});
  }
  EXPECT_LT((stencil.displacement() - elementwise->u()).norm(), 1e-9 * elementwise->u().norm());
}

// Per step: H after − H before = load work + prescribed work − damping − controlled damping,
// exactly (to round-off), with a load the port limit cuts and extra damping on DOFs of both
// materials. Returns the worst residual relative to the starting energy.
double WorstBalanceResidual(const ElasticModel& model, double* controlled_total) {
  const double dt = StableStep(model);
  std::vector<int> loaded;  // the nodes at x = 3, 4, 5: either side of the two halves
  for (int ix = 3; ix <= 5; ++ix) {
    for (int c = 0; c < 3; ++c) loaded.push_back(kBar.Dof(kBar.Node(ix, 1, 1), c));
  }
  auto region = WholeBar(model, dt, loaded);
  const std::vector<double> held(model.constraints().fixed_dofs.size(), 0.0);
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> uniform(-1e-3, 1e-3);
  std::vector<double> load(loaded.size());
  const double start = region->DiscreteEnergy();
  double worst = 0;
  *controlled_total = 0;
  for (int n = 0; n < 3000; ++n) {
    for (double& f : load) f = uniform(rng);
    const double before = region->DiscreteEnergy();
    PortWorkLimits limits;
    limits.load_work_j = 1e-12;
    const double dissipate = 1e-3 * before;
    region->Step(held, load, dissipate, limits);
    double prescribed = 0;
    for (size_t k = 0; k < held.size(); ++k) {
      prescribed += region->PrescribedWork(static_cast<int>(k));
    }
    const double residual = region->DiscreteEnergy() - before -
                            (region->LoadWork() + prescribed - region->DampingDissipated() -
                             region->ControlledDissipated());
    worst = std::max(worst, std::abs(residual) / start);
    EXPECT_LE(region->LoadWork(), 1e-12 * (1 + 1e-9));
    EXPECT_LE(region->ControlledDissipated(), dissipate * (1 + 1e-12));
    EXPECT_GE(region->DampingDissipated(), 0.0);
    *controlled_total += region->ControlledDissipated();
  }
  return worst;
}

TEST(Damping, PerDofDampingKeepsTheEnergyBalanceAsExactlyAsOneRate) {
  const ElasticModel uniform(kBar, Halves(Damped(4), Damped(4)), HeldAtXZero());
  const ElasticModel mixed(kBar, Halves(Damped(2), Damped(6)), HeldAtXZero());
  double uniform_controlled = 0, mixed_controlled = 0;
  const double uniform_worst = WorstBalanceResidual(uniform, &uniform_controlled);
  const double mixed_worst = WorstBalanceResidual(mixed, &mixed_controlled);
  std::printf("balance residual per step / H₀: one rate %.3g, two rates %.3g; controlled "
              "dissipated %.3g J and %.3g J\n",
              uniform_worst, mixed_worst, uniform_controlled, mixed_controlled);
  EXPECT_LT(uniform_worst, 1e-12);
  EXPECT_LT(mixed_worst, 1e-12);
  EXPECT_GT(mixed_controlled, 0.0);
}

// Free vibration: what the bar started with is what it holds plus what its damping took.
TEST(Damping, FreeVibrationEnergyIsHeldPlusDissipated) {
  for (const auto& [d1, d2] : {std::pair{4.0, 4.0}, std::pair{2.0, 6.0}}) {
    const ElasticModel model(kBar, Halves(Damped(d1), Damped(d2)), HeldAtXZero());
    const double dt = StableStep(model);
    auto region = WholeBar(model, dt);
    const std::vector<double> held(model.constraints().fixed_dofs.size(), 0.0);
    const double start = region->DiscreteEnergy();
    double dissipated = 0;
    for (int n = 0; n < 5000; ++n) {
      region->Step(held, {});
      dissipated += region->DampingDissipated();
    }
    const double error = std::abs(start - region->DiscreteEnergy() - dissipated) / start;
    std::printf("d %.0f/%.0f: |H₀ − H − dissipated|/H₀ = %.3g after %.3g s (H/H₀ = %.3g)\n", d1,
                d2, error, 5000 * dt, region->DiscreteEnergy() / start);
    EXPECT_LT(error, 1e-10);
  }
}

}  // namespace
}  // namespace hapticsim
