// An object of any shape and several materials on the lattice (MaterialField, the
// element-by-element ElementwiseStiffness and ElasticModel over it), checked against what does not
// depend on it: the assembled matrix built from the same field, the uniform cube's stencil, the
// invariants of linear elasticity on a non-box shape (symmetry, rigid-body modes, the patch test,
// linearity), and the analytical stiffness of a two-material bar (springs in series), exact with
// ν = 0 and converging under mesh refinement with ν = 0.3.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <numeric>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "core/error.hpp"
#include "core/fem/assembled_stiffness.hpp"
#include "core/fem/central_difference_integrator.hpp"
#include "core/fem/elastic_model.hpp"
#include "core/fem/elementwise_stiffness.hpp"
#include "core/fem/material_field.hpp"
#include "core/fem/stability_estimate.hpp"
#include "core/fem/static_solver.hpp"
#include "core/fem/stencil_stiffness.hpp"
#include "tests/support/random_field.hpp"

namespace hapticsim {
namespace {

constexpr double kH = 0.02;

Material Soft() { return Material{}; }  // 10 kPa, ν 0.45, 1000 kg/m³
Material Stiff() {
  Material m;
  m.youngs_modulus_pa = 80e3;  // an inclusion 8 times stiffer, and denser
  m.poisson_ratio = 0.3;
  m.density_kg_m3 = 1200;
  return m;
}

// Elements labelled by `label(ex, ey, ez)`: kEmpty, 0 (soft) or 1 (stiff).
MaterialField FieldOf(const HexGrid& grid,
                      const std::function<std::int16_t(int, int, int)>& label,
                      std::vector<Material> materials = {Soft(), Stiff()}) {
  std::vector<std::int16_t> elements(static_cast<size_t>(grid.num_elements()));
  for (int ez = 0; ez + 1 < grid.nz(); ++ez) {
    for (int ey = 0; ey + 1 < grid.ny(); ++ey) {
      for (int ex = 0; ex + 1 < grid.nx(); ++ex) {
        elements[static_cast<size_t>(ex + (grid.nx() - 1) * (ey + (grid.ny() - 1) * ez))] =
            label(ex, ey, ez);
      }
    }
  }
  return MaterialField(grid, std::move(materials), std::move(elements));
}

// An L: the grid's box less its upper-right quarter in x and y, soft with a stiff block in it.
MaterialField LShape(const HexGrid& grid) {
  return FieldOf(grid, [&](int ex, int ey, int ez) -> std::int16_t {
    if (2 * ex >= grid.nx() - 1 && 2 * ey >= grid.ny() - 1) return MaterialField::kEmpty;
    return ex <= 1 && ey <= 1 && ez >= 1 ? 1 : 0;
  });
}

double RelativeDifference(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  return (a - b).norm() / std::max(b.norm(), 1e-300);
}

TEST(ElementwiseStiffness, MatchesTheAssembledMatrixOnARandomTwoMaterialShape) {
  const HexGrid grid(6, 5, 7, kH);
  std::uint64_t state = 12345;
  const MaterialField field = FieldOf(grid, [&](int, int, int) -> std::int16_t {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    const int draw = static_cast<int>((state >> 33) % 10);
    return draw < 3 ? MaterialField::kEmpty : draw < 7 ? 0 : 1;
  });
  const ElementwiseStiffness dut(grid, field);
  const AssembledStiffness oracle(grid, field);
  ASSERT_EQ(dut.num_elements(), field.num_occupied());
  for (int seed = 1; seed <= 3; ++seed) {
    const Eigen::VectorXd u = testing::RandomField(grid.num_dofs(), seed, 1e-3);
    Eigen::VectorXd ku(grid.num_dofs()), expected(grid.num_dofs());
    dut.Apply(u, ku);
    oracle.Apply(u, expected);
    EXPECT_LT(RelativeDifference(ku, expected), 1e-13) << "seed " << seed;
  }
  EXPECT_LT(RelativeDifference(dut.Diagonal(), oracle.Diagonal()), 1e-14);
}

TEST(ElementwiseStiffness, MatchesTheStencilOnTheUniformFullCube) {
  const HexGrid grid(7, 7, 7, kH);
  const ElementwiseStiffness dut(grid, MaterialField(grid, Soft()));
  const StencilStiffness stencil(grid, Soft());
  const Eigen::VectorXd u = testing::RandomField(grid.num_dofs(), 5, 1e-3);
  Eigen::VectorXd ku(grid.num_dofs()), expected(grid.num_dofs());
  dut.Apply(u, ku);
  stencil.Apply(u, expected);
  EXPECT_LT(RelativeDifference(ku, expected), 1e-13);
  EXPECT_LT(RelativeDifference(dut.Diagonal(), stencil.Diagonal()), 1e-14);
}

// Three materials on a masked grid, with long runs of one stencil along x (a soft slab, a stiff
// block), short ones (a layer of materials drawn at random) and nodes no element touches (an
// empty corner above): every segment kind of the node-stencil kernel, at the grid's faces too.
MaterialField MixedMaskedField(const HexGrid& grid) {
  std::uint64_t state = 777;
  return FieldOf(
      grid,
      [&](int ex, int ey, int ez) -> std::int16_t {
        state = state * 6364136223846793005ull + 1442695040888963407ull;
        const int draw = static_cast<int>((state >> 33) % 4);
        if (ez == grid.nz() - 2) {
          return ey >= 2 ? MaterialField::kEmpty : static_cast<std::int16_t>(draw == 3 ? -1 : draw);
        }
        if (ez == 1) return static_cast<std::int16_t>(draw == 3 ? -1 : draw);  // short runs
        return ex >= 3 && ex <= 8 && ey >= 1 ? 1 : 0;
      },
      {Soft(), Stiff(), Material{2e4, 0.35, 1100, 0}});
}

// Both kernels, and the one chosen, against the matrix assembled from the same field. ku starts
// as NaN: Apply must assign every entry, 0 exactly where no element touches the node.
TEST(ElementwiseStiffness, EveryKernelMatchesTheAssembledMatrixOnAMixedMaskedField) {
  using Kernel = ElementwiseStiffness::Kernel;
  for (const HexGrid& grid : {HexGrid(12, 5, 5, kH), HexGrid(3, 4, 4, kH), HexGrid(5, 3, 4, kH)}) {
    const MaterialField field = MixedMaskedField(grid);
    const AssembledStiffness oracle(grid, field);
    const std::vector<bool> active = field.ActiveNodes(grid);
    ASSERT_LT(std::count(active.begin(), active.end(), true), grid.num_nodes());
    for (const Kernel kernel : {Kernel::kNodeStencils, Kernel::kElements, Kernel::kAuto}) {
      const ElementwiseStiffness dut(grid, field, kernel);
      if (kernel != Kernel::kAuto) {
        ASSERT_EQ(dut.kernel(), kernel);
      }
      const std::string label = "grid " + std::to_string(grid.nx()) + ", kernel " +
                                std::to_string(static_cast<int>(dut.kernel()));
      for (int seed = 1; seed <= 3; ++seed) {
        const Eigen::VectorXd u = testing::RandomField(grid.num_dofs(), seed, 1e-3);
        Eigen::VectorXd ku = Eigen::VectorXd::Constant(grid.num_dofs(), std::nan("")),
                        expected(grid.num_dofs());
        dut.Apply(u, ku);
        oracle.Apply(u, expected);
        ASSERT_TRUE(ku.allFinite()) << label;
        EXPECT_LT(RelativeDifference(ku, expected), 1e-13) << label << ", seed " << seed;
        for (int node = 0; node < grid.num_nodes(); ++node) {
          if (active[static_cast<size_t>(node)]) continue;
          for (int c = 0; c < 3; ++c) EXPECT_EQ(ku[grid.Dof(node, c)], 0.0) << label;
        }
      }
      EXPECT_LT(RelativeDifference(dut.Diagonal(), oracle.Diagonal()), 1e-14) << label;
    }
  }
}

// The field above does give the node-stencil kernel merged windows (short runs) besides its
// stencils, so the test above went through both of its paths.
TEST(ElementwiseStiffness, TheMixedFieldExercisesWindowsAndLongRuns) {
  const HexGrid grid(12, 5, 5, kH);
  const ElementwiseStiffness dut(grid, MixedMaskedField(grid),
                                 ElementwiseStiffness::Kernel::kNodeStencils);
  EXPECT_GT(dut.num_lane_stencils(), 0);
  EXPECT_GT(dut.num_stencils(), 10);
}

// The choice: one material in a masked slab runs the node stencils (long runs); a field drawn at
// random element by element from three materials and empty, on 25³, has more distinct cell
// tuples than stay in cache (nearly one per node), and runs the elements.
TEST(ElementwiseStiffness, ChoosesNodeStencilsOnASlabAndElementsOnAFieldMixedAtRandom) {
  const HexGrid grid(13, 13, 13, kH);
  const MaterialField slab = FieldOf(grid, [](int, int, int ez) -> std::int16_t {
    return ez < 6 ? 0 : MaterialField::kEmpty;
  });
  EXPECT_EQ(ElementwiseStiffness(grid, slab).kernel(),
            ElementwiseStiffness::Kernel::kNodeStencils);
  const HexGrid large(25, 25, 25, kH);
  std::uint64_t state = 99;
  const MaterialField random = FieldOf(
      large,
      [&](int, int, int) -> std::int16_t {
        state = state * 6364136223846793005ull + 1442695040888963407ull;
        return static_cast<std::int16_t>((state >> 33) % 4 - 1);
      },
      {Soft(), Stiff(), Material{2e4, 0.35, 1100, 0}});
  EXPECT_EQ(ElementwiseStiffness(large, random).kernel(), ElementwiseStiffness::Kernel::kElements);
}

TEST(ElementwiseStiffness, IsSymmetricAndHasTheSixRigidBodyModesOnAnLShape) {
  const HexGrid grid(7, 7, 4, kH);
  const MaterialField field = LShape(grid);
  const ElementwiseStiffness k(grid, field);
  const Eigen::VectorXd u = testing::RandomField(grid.num_dofs(), 1, 1e-3);
  const Eigen::VectorXd v = testing::RandomField(grid.num_dofs(), 2, 1e-3);
  Eigen::VectorXd ku(grid.num_dofs()), kv(grid.num_dofs());
  k.Apply(u, ku);
  k.Apply(v, kv);
  const double scale = ku.norm() * v.norm();
  EXPECT_LT(std::abs(v.dot(ku) - u.dot(kv)), 1e-13 * scale);

  // Three translations and three infinitesimal rotations about the grid's centre: no force.
  const std::vector<bool> active = field.ActiveNodes(grid);
  for (int mode = 0; mode < 6; ++mode) {
    Eigen::VectorXd rigid = Eigen::VectorXd::Zero(grid.num_dofs());
    for (int node = 0; node < grid.num_nodes(); ++node) {
      if (!active[static_cast<size_t>(node)]) continue;
      const auto p = grid.NodePosition(node);
      const Eigen::Vector3d x(p[0] - 0.06, p[1] - 0.06, p[2] - 0.03);
      Eigen::Vector3d value = Eigen::Vector3d::Zero();
      if (mode < 3) {
        value[mode] = 1e-3;
      } else {
        const Eigen::Vector3d axis = Eigen::Vector3d::Unit(mode - 3);
        value = axis.cross(x) * 1e-2;
      }
      for (int c = 0; c < 3; ++c) rigid[grid.Dof(node, c)] = value[c];
    }
    Eigen::VectorXd force(grid.num_dofs());
    k.Apply(rigid, force);
    // Against the force of a deformation of the same size.
    EXPECT_LT(force.norm(), 1e-12 * ku.norm() * rigid.norm() / u.norm()) << "mode " << mode;
  }
}

// The patch test on the L (one material: an affine field is in equilibrium only in a homogeneous
// body): no force at nodes inside the shape, and a static solve with the affine values held on
// the shape's surface returns them inside.
TEST(ElementwiseStiffness, PassesThePatchTestOnAnLShape) {
  const HexGrid grid(7, 7, 5, kH);
  const MaterialField l = LShape(grid);
  std::vector<std::int16_t> one(static_cast<size_t>(grid.num_elements()));
  for (int e = 0; e < grid.num_elements(); ++e) one[static_cast<size_t>(e)] = l.occupied(e) ? 0 : -1;
  const MaterialField field(grid, {Soft()}, one);
  const std::vector<bool> active = field.ActiveNodes(grid);
  // A node is inside the shape when all 8 elements around it are occupied.
  auto inside = [&](int node) {
    const auto [ix, iy, iz] = grid.NodeIndices(node);
    for (int dz = -1; dz <= 0; ++dz) {
      for (int dy = -1; dy <= 0; ++dy) {
        for (int dx = -1; dx <= 0; ++dx) {
          const int ex = ix + dx, ey = iy + dy, ez = iz + dz;
          if (ex < 0 || ey < 0 || ez < 0 || ex >= grid.nx() - 1 || ey >= grid.ny() - 1 ||
              ez >= grid.nz() - 1 || !field.occupied(field.Element(ex, ey, ez))) {
            return false;
          }
        }
      }
    }
    return true;
  };
  const Eigen::VectorXd r = testing::RandomField(12, 7, 1e-2);
  const Eigen::Matrix3d a = Eigen::Map<const Eigen::Matrix3d>(r.data());
  const Eigen::Vector3d b = r.tail<3>();
  Eigen::VectorXd affine = Eigen::VectorXd::Zero(grid.num_dofs());
  DofConstraints constraints;
  std::vector<double> values;
  int inside_nodes = 0;
  for (int node = 0; node < grid.num_nodes(); ++node) {
    if (!active[static_cast<size_t>(node)]) continue;
    const auto p = grid.NodePosition(node);
    const Eigen::Vector3d value = a * Eigen::Vector3d(p[0], p[1], p[2]) + b;
    for (int c = 0; c < 3; ++c) affine[grid.Dof(node, c)] = value[c];
    if (inside(node)) {
      ++inside_nodes;
      continue;
    }
    for (int c = 0; c < 3; ++c) {
      constraints.driven_dofs.push_back(grid.Dof(node, c));
      values.push_back(value[c]);
    }
  }
  ASSERT_GT(inside_nodes, 10);
  const ElasticModel model(grid, field, constraints);
  Eigen::VectorXd force(grid.num_dofs());
  model.stiffness().Apply(affine, force);
  const double scale = force.cwiseAbs().maxCoeff();
  ASSERT_GT(scale, 0.0);
  const StaticSolution solved = SolveStatic(model, values, 1e-13);
  ASSERT_TRUE(solved.converged);
  for (int node = 0; node < grid.num_nodes(); ++node) {
    if (!inside(node)) continue;
    for (int c = 0; c < 3; ++c) {
      const int dof = grid.Dof(node, c);
      EXPECT_LT(std::abs(force[dof]), 1e-12 * scale) << "node " << node;
      EXPECT_NEAR(solved.displacement[dof], affine[dof], 1e-10 * affine.cwiseAbs().maxCoeff());
    }
  }
}

TEST(ElasticModel, OnTwoMaterialsTheStaticSolveIsLinear) {
  const HexGrid grid(7, 7, 4, kH);
  DofConstraints constraints;
  for (int ix = 0; ix < 3; ++ix) {  // the L's foot held on its back face, its front pressed
    for (int iy = 0; iy < 3; ++iy) {
      for (int c = 0; c < 3; ++c) constraints.fixed_dofs.push_back(grid.Dof(grid.Node(ix, iy, 3), c));
      constraints.driven_dofs.push_back(grid.Dof(grid.Node(ix, iy, 0), 2));
    }
  }
  const ElasticModel model(grid, LShape(grid), constraints);
  const size_t n = constraints.driven_dofs.size();
  std::vector<double> first(n), second(n), sum(n);
  for (size_t i = 0; i < n; ++i) {
    first[i] = 1e-3 * (1 + static_cast<double>(i % 3));
    second[i] = -5e-4 * (1 + static_cast<double>(i % 4));
    sum[i] = 2 * first[i] + second[i];
  }
  const StaticSolution a = SolveStatic(model, first, 1e-13);
  const StaticSolution b = SolveStatic(model, second, 1e-13);
  const StaticSolution c = SolveStatic(model, sum, 1e-13);
  ASSERT_TRUE(a.converged && b.converged && c.converged);
  EXPECT_LT(RelativeDifference(c.displacement, 2 * a.displacement + b.displacement), 1e-10);
  // Off the shape nothing moves.
  const std::vector<bool> active = model.field().ActiveNodes(grid);
  for (int node = 0; node < grid.num_nodes(); ++node) {
    if (active[static_cast<size_t>(node)]) continue;
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(c.displacement[grid.Dof(node, k)], 0.0);
      EXPECT_EQ(model.free_mask()[grid.Dof(node, k)], 0.0);
      EXPECT_EQ(model.dof_mass()[grid.Dof(node, k)], 0.0);
    }
  }
}

TEST(ElasticModel, LumpsEachElementsOwnMass) {
  const HexGrid grid(7, 7, 4, kH);
  const ElasticModel model(grid, LShape(grid), {});
  double expected = 0;
  for (int e = 0; e < grid.num_elements(); ++e) {
    const std::int16_t m = model.field().material_of(e);
    if (m != MaterialField::kEmpty) {
      expected += model.field().materials()[static_cast<size_t>(m)].density_kg_m3 * kH * kH * kH;
    }
  }
  const double total = model.dof_mass().head(grid.num_nodes()).sum();
  EXPECT_NEAR(total, expected, 1e-12 * expected);
  // One material everywhere: the cube's closed form, to the bit — ρh³/8 times the elements
  // around a node (1, 2, 4 or 8) — and the stencil operator.
  const ElasticModel cube(grid, MaterialField(grid, Soft()), {});
  const double share = Soft().density_kg_m3 * kH * kH * kH / 8.0;
  for (int node = 0; node < grid.num_nodes(); ++node) {
    const auto idx = grid.NodeIndices(node);
    const std::array<int, 3> counts{grid.nx(), grid.ny(), grid.nz()};
    int adjacent = 1;
    for (int axis = 0; axis < 3; ++axis) {
      adjacent *= idx[axis] == 0 || idx[axis] == counts[axis] - 1 ? 1 : 2;
    }
    for (int c = 0; c < 3; ++c) ASSERT_EQ(cube.dof_mass()[grid.Dof(node, c)], adjacent * share);
  }
  EXPECT_NE(dynamic_cast<const StencilStiffness*>(&cube.stiffness()), nullptr);
  // A second material listed but used nowhere changes nothing: still the stencil, and its
  // stiffness does not bound the time step.
  const ElasticModel listed(grid, MaterialField(grid, {Soft(), Stiff()},
                                                std::vector<std::int16_t>(
                                                    static_cast<size_t>(grid.num_elements()), 0)),
                            {});
  EXPECT_NE(dynamic_cast<const StencilStiffness*>(&listed.stiffness()), nullptr);
  EXPECT_EQ(ElementBoundCriticalDt(listed), ElementBoundCriticalDt(cube));
}

// A quarter of a square bar (symmetry planes y = 0 and z = 0, rollers at x = 0), 8 × 2 × 2 units
// of edge kH, soft in its first half and `ratio` times stiffer in its second, its end face pulled
// 1 mm along x with n elements per unit: the reaction over that pull, N/m.
double BarStiffness(int n, double poisson_ratio, double ratio) {
  const HexGrid grid(8 * n + 1, 2 * n + 1, 2 * n + 1, kH / n);
  Material soft = Soft(), stiff = Soft();
  soft.poisson_ratio = stiff.poisson_ratio = poisson_ratio;
  stiff.youngs_modulus_pa = ratio * soft.youngs_modulus_pa;
  const MaterialField field =
      FieldOf(grid, [&](int ex, int, int) -> std::int16_t { return ex < 4 * n ? 0 : 1; },
              {soft, stiff});
  DofConstraints constraints;
  for (int node = 0; node < grid.num_nodes(); ++node) {
    const auto [ix, iy, iz] = grid.NodeIndices(node);
    if (ix == 0) constraints.fixed_dofs.push_back(grid.Dof(node, 0));
    if (iy == 0) constraints.fixed_dofs.push_back(grid.Dof(node, 1));
    if (iz == 0) constraints.fixed_dofs.push_back(grid.Dof(node, 2));
    if (ix == grid.nx() - 1) constraints.driven_dofs.push_back(grid.Dof(node, 0));
  }
  const ElasticModel model(grid, field, constraints);
  const std::vector<double> pulled(constraints.driven_dofs.size(), 1e-3);
  const StaticSolution solved = SolveStatic(model, pulled, 1e-13);
  EXPECT_TRUE(solved.converged);
  return std::accumulate(solved.driven_reaction.begin(), solved.driven_reaction.end(), 0.0) /
         1e-3;
}

// Springs in series: k = A / (L₁/E₁ + L₂/E₂), A the quarter section (2 kH)², L₁ = L₂ = 4 kH.
double SeriesStiffness(double ratio) {
  const double e = Soft().youngs_modulus_pa, area = 4 * kH * kH, half = 4 * kH;
  return area / (half / e + half / (ratio * e));
}

TEST(TwoMaterialBar, WithoutLateralContractionIsSpringsInSeriesOnEveryMesh) {
  // ν = 0: the exact solution is uniaxial stress with u_x piecewise linear, which the trilinear
  // elements hold exactly when the interface lies on element faces.
  for (int n : {1, 2, 3}) {
    const double k = BarStiffness(n, 0.0, 5.0);
    EXPECT_NEAR(k, SeriesStiffness(5.0), 1e-8 * SeriesStiffness(5.0)) << n << " per unit";
  }
}

TEST(TwoMaterialBar, WithLateralContractionConvergesNearSpringsInSeries) {
  // ν = 0.3: the two halves contract sideways by different amounts under the same stress, and
  // the interface holds them together: the continuum is slightly stiffer than the series, and
  // the mesh converges to it.
  const double series = SeriesStiffness(5.0);
  std::vector<double> k;
  for (int n : {1, 2, 4}) k.push_back(BarStiffness(n, 0.3, 5.0));
  std::printf("two-material bar, nu 0.3, E ratio 5: k = %.6f, %.6f, %.6f N/m at 1, 2, 4 elements "
              "per unit; springs in series %.6f N/m\n",
              k[0], k[1], k[2], series);
  // Stiffer from above: a conforming mesh is too stiff, and less so as it is refined.
  EXPECT_GT(k[0], k[1]);
  EXPECT_GT(k[1], k[2]);
  EXPECT_GE(k[2], series);
  // Converging: each refinement changes it less than half as much as the one before.
  EXPECT_LT(k[1] - k[2], 0.5 * (k[0] - k[1]));
  EXPECT_LT((k[2] - series) / series, 0.02);
}

TEST(ElasticModel, TheStabilityLimitIsTheStiffestLightestMaterials) {
  const HexGrid grid(6, 6, 6, kH);
  const ElasticModel both(grid, LShape(grid), {});
  const ElasticModel soft(grid, Soft(), {}), stiff(grid, Stiff(), {});
  EXPECT_EQ(ElementBoundCriticalDt(both),
            std::min(ElementBoundCriticalDt(soft), ElementBoundCriticalDt(stiff)));
  EXPECT_LT(ElementBoundCriticalDt(both), ElementBoundCriticalDt(soft));
  // The bound is never above the true limit (the Lanczos estimate over the whole shape).
  const StabilityEstimate estimate = EstimateStability(both);
  EXPECT_GE(estimate.critical_dt_s, estimate.element_bound_dt_s);
}

// The time step on the L of two materials, undamped, held on its back face, from a random
// displacement: central difference conserves its shadow energy exactly (½(u⁺ − u)ᵀM(u⁺ − u)/dt²
// + ½uᵀK u⁺, telescoping), stable just below the Lanczos limit of the shape, and its divergence
// caught just above it.
TEST(TwoMaterialL, UndampedVibrationConservesEnergyAndTheLimitIsThePredictedOne) {
  const HexGrid grid(7, 7, 4, kH);
  Material soft = Soft(), stiff = Stiff();
  soft.damping_per_s = stiff.damping_per_s = 0;
  DofConstraints constraints;
  for (int ix = 0; ix < 3; ++ix) {
    for (int iy = 0; iy < 3; ++iy) {
      for (int c = 0; c < 3; ++c) constraints.fixed_dofs.push_back(grid.Dof(grid.Node(ix, iy, 3), c));
    }
  }
  constraints.driven_dofs = {grid.Dof(grid.Node(1, 1, 0), 2)};
  const MaterialField l = LShape(grid);
  std::vector<std::int16_t> elements(static_cast<size_t>(grid.num_elements()));
  for (int e = 0; e < grid.num_elements(); ++e) elements[static_cast<size_t>(e)] = l.material_of(e);
  const ElasticModel model(grid, MaterialField(grid, {soft, stiff}, elements), constraints);
  const double critical = EstimateStability(model).critical_dt_s;
  const Eigen::VectorXd u0 =
      testing::RandomField(grid.num_dofs(), 3, 1e-4).cwiseProduct(model.free_mask());
  const std::array<double, 1> held{0};

  CentralDifferenceIntegrator below(model, 0.99 * critical);
  below.SetState(u0, u0);
  double first = 0, worst_drift = 0;
  for (int n = 0; n < 10000; ++n) {
    const Eigen::VectorXd before = below.displacement();
    ASSERT_EQ(below.Step(held), StepStatus::kOk) << "step " << n;
    Eigen::VectorXd k_next(grid.num_dofs());
    model.stiffness().Apply(below.displacement(), k_next);
    const Eigen::VectorXd du = below.displacement() - before;
    const double shadow = 0.5 * du.cwiseProduct(model.dof_mass()).dot(du) /
                              (0.99 * critical * 0.99 * critical) +
                          0.5 * before.dot(k_next);
    if (n == 0) first = shadow;
    worst_drift = std::max(worst_drift, std::abs(shadow - first));
  }
  EXPECT_GT(first, 0.0);
  EXPECT_LT(worst_drift, 1e-9 * first);

  CentralDifferenceIntegrator above(model, 1.01 * critical);
  above.SetState(u0, u0);
  int detected_at = -1;
  for (int n = 0; n < 4000 && detected_at < 0; ++n) {
    if (above.Step(held) != StepStatus::kOk) detected_at = n;
  }
  EXPECT_GE(detected_at, 0) << "divergence at 1.01 × the predicted limit not detected";
}

TEST(MaterialField, RefusesWhatIsNotAnObjectSayingWhy) {
  const HexGrid grid(3, 3, 3, kH);
  const std::vector<std::int16_t> all(8, 0);
  auto message = [](const std::function<void()>& make) {
    try {
      make();
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("(accepted)");
  };
  Material incompressible;
  incompressible.poisson_ratio = 0.5;
  EXPECT_NE(message([&] { MaterialField(grid, {incompressible}, all); })
                .find("material 0: Poisson's ratio must be in (-1, 0.5)"),
            std::string::npos);
  EXPECT_NE(message([&] { MaterialField(grid, {Soft()}, std::vector<std::int16_t>(8, 1)); })
                .find("element 0 names material 1; there are 1"),
            std::string::npos);
  EXPECT_NE(message([&] {
              MaterialField(grid, {Soft()}, std::vector<std::int16_t>(8, MaterialField::kEmpty));
            }).find("fills no element"),
            std::string::npos);
  EXPECT_NE(message([&] { MaterialField(grid, {Soft()}, std::vector<std::int16_t>(7, 0)); })
                .find("the material field has 7 elements; the grid has 8"),
            std::string::npos);
  const HexGrid other(3, 5, 2, kH);  // as many elements, in another shape
  EXPECT_NE(message([&] { ElasticModel(other, MaterialField(grid, Soft()), {}); })
                .find("the material field was made for 2 × 2 × 2 elements; the grid has 2 × 4 × 1"),
            std::string::npos);
  // A support or a contact where no element is: refused, not silently without a reaction.
  std::vector<std::int16_t> corner = all;
  corner[7] = MaterialField::kEmpty;  // the element at (1, 1, 1): node (2, 2, 2) is off it
  DofConstraints off;
  off.driven_dofs = {grid.Dof(grid.Node(2, 2, 2), 2)};
  EXPECT_NE(message([&] { ElasticModel(grid, MaterialField(grid, {Soft()}, corner), off); })
                .find("is off the object: no element touches it"),
            std::string::npos);
}

}  // namespace
}  // namespace hapticsim
