// The object's motion carried from one configuration of the regions to another
// (AsyncRegions::CaptureState / RestoreState), as hapticsimd does when it switches configurations
// while the tool presses. Checked against what is independent of the transfer: regions at
// spacing factor 1 and one rate are monolithic central difference, so a switch between two of
// them must continue the unswitched run to round-off; the transfer must keep what the fine lattice
// holds exactly; and a switch between multirate configurations in the middle of the paper's press
// must not step the force.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "core/regions/async_regions.hpp"
#include "core/error.hpp"
#include "tests/support/adaptive_scene.hpp"

namespace hapticsim {
namespace {

// The scene's press from period `from` up to `to` (exclusive) on `regions`, stepped as RunTrial
// steps it (the secondaries first, as far as the primary's coming step needs): the force on the
// user along z, N, one per period.
std::vector<double> Press(AsyncRegions& regions, long from, long to) {
  const Scene& scene = regions.partition().scene();
  const ContactTrajectory trajectory(scene.input, InwardNormal(scene.mesh, ContactNode(scene)));
  const int substeps = regions.schedule(kPrimaryRegion).substeps;
  const double dt = scene.solver.dt_s, h = dt / substeps;
  std::vector<double> force_z;
  for (long n = from; n < to; ++n) {
    std::array<double, 3> reaction{};
    for (int q = 1; q <= substeps; ++q) {
      regions.AdvanceSecondariesTo(regions.state_ticks(kPrimaryRegion) +
                                   regions.period_ticks(kPrimaryRegion));
      const std::array<double, 3> r =
          regions.StepPrimary(trajectory.DisplacementAt(n * dt + q * h));
      if (q == 1) reaction = r;
    }
    force_z.push_back(-reaction[2]);
  }
  return force_z;
}

// Period `switch_at` of the press on `from`, the rest on `to` started from `from`'s state.
std::vector<double> PressSwitching(const Scene& from, const Scene& to, long switch_at,
                                   long periods) {
  AsyncRegions before(from);
  before.Reset();
  std::vector<double> force_z = Press(before, 0, switch_at);
  AsyncRegions after(to);
  after.RestoreState(before.CaptureState());
  const std::vector<double> rest = Press(after, switch_at, periods);
  force_z.insert(force_z.end(), rest.begin(), rest.end());
  return force_z;
}

std::vector<double> PressWhole(const Scene& scene, long periods) {
  AsyncRegions regions(scene);
  regions.Reset();
  return Press(regions, 0, periods);
}

double LargestStep(const std::vector<double>& force, size_t from, size_t to) {
  double largest = 0;
  for (size_t n = std::max<size_t>(from, 1); n < to && n < force.size(); ++n) {
    largest = std::max(largest, std::abs(force[n] - force[n - 1]));
  }
  return largest;
}

TEST(StateTransfer, BetweenFullResolutionConfigurationsAtOneRateTheMotionContinuesToRoundOff) {
  // Both configurations are the monolithic scheme (k 1, one rate): only summation order separates
  // them, so whatever the transfer loses shows as a departure from the unswitched run.
  const Scene small = testing::AdaptiveScene(1, 1, 1000);
  const Scene large = testing::AdaptiveScene(3, 1, 1000);
  const long periods = 1000;
  const std::vector<double> whole = PressWhole(small, periods);
  const double peak = *std::max_element(
      whole.begin(), whole.end(), [](double a, double b) { return std::abs(a) < std::abs(b); });
  ASSERT_GT(std::abs(peak), 1.0) << "the paper's press peaks near 1.5 N";
  for (long switch_at : {250L, 500L, 730L}) {
    for (const auto& [from, to] : {std::pair{small, large}, std::pair{large, small}}) {
      const std::vector<double> switched = PressSwitching(from, to, switch_at, periods);
      double largest = 0;
      for (size_t n = 0; n < whole.size(); ++n) {
        largest = std::max(largest, std::abs(switched[n] - whole[n]));
      }
      EXPECT_LT(largest, 1e-9 * std::abs(peak))
          << "switched at period " << switch_at << " from primary size "
          << from.adaptivity.primary_size << " to " << to.adaptivity.primary_size;
    }
  }
}

TEST(StateTransfer, KeepsWhatTheFineLatticeHoldsAndInterpolatesTheCoarseCells) {
  // A state captured from full-resolution regions and restored into coarse ones and back: every
  // lattice point that is a node of the coarse configuration keeps its value exactly; the others
  // take the coarse cells' trilinear field, which reproduces a trilinear field exactly.
  const Scene fine = testing::AdaptiveScene(2, 1, 1000);
  const Scene coarse = testing::AdaptiveScene(2, 2, 600);
  ObjectState linear;
  const int n = fine.mesh.nodes;
  linear.lattice_nodes = {n, n, n};
  linear.displacement_m.assign(static_cast<size_t>(3 * n * n * n), 0.0);
  linear.velocity_m_per_s = linear.displacement_m;
  for (int ix = 0; ix < n; ++ix) {
    for (int iy = 0; iy < n; ++iy) {
      for (int iz = 0; iz < n; ++iz) {
        const size_t i = linear.Index(ix, iy, iz);
        // Zero on the supports (the back face's corners, z index n − 1): they stay fixed.
        const double zeta = 1e-4 * (n - 1 - iz);
        linear.displacement_m[i] = zeta * (1 + 0.1 * ix);
        linear.displacement_m[i + 1] = 0.5 * zeta;
        linear.displacement_m[i + 2] = zeta * 0.2 * iy;
        for (int c = 0; c < 3; ++c)
          linear.velocity_m_per_s[i + c] = 3 * linear.displacement_m[i + c];
      }
    }
  }
  AsyncRegions coarse_regions(coarse);
  coarse_regions.RestoreState(linear);
  const ObjectState through_coarse = coarse_regions.CaptureState();
  AsyncRegions fine_regions(fine);
  fine_regions.RestoreState(through_coarse);
  const ObjectState back = fine_regions.CaptureState();
  double largest = 0, largest_velocity = 0;
  for (size_t i = 0; i < back.displacement_m.size(); ++i) {
    largest = std::max(largest, std::abs(back.displacement_m[i] - linear.displacement_m[i]));
    largest_velocity =
        std::max(largest_velocity, std::abs(back.velocity_m_per_s[i] - linear.velocity_m_per_s[i]));
  }
  // The field is trilinear in the lattice indices (x·z, y·z terms), which trilinear cells
  // reproduce exactly: the round trip must give it back to round-off.
  EXPECT_LT(largest, 1e-15);
  EXPECT_LT(largest_velocity, 1e-13);
}

// The value at lattice point p of the field the coarse elements interpolate from `at_nodes` (one
// value per independent node): found independently of the transfer's own cell arithmetic, by
// looking for a coarse element whose box holds p and evaluating its trilinear shape functions.
double ElementField(const HybridMesh& mesh, const std::vector<double>& at_nodes,
                    const std::array<int, 3>& p) {
  for (const HybridElement& e : mesh.elements()) {
    if (e.size_factor == 1) continue;
    std::array<int, 3> lo{1 << 30, 1 << 30, 1 << 30};
    std::array<int, 8> corner{};
    for (int local = 0; local < 8; ++local) {
      const auto [begin, end] = mesh.Gather(e.nodes[local]);
      corner[local] = begin->independent;  // a coarse element's vertices are independent
      for (int d = 0; d < 3; ++d) lo[d] = std::min(lo[d], mesh.LatticeOf(begin->independent)[d]);
    }
    bool inside = true;
    for (int d = 0; d < 3; ++d) inside = inside && p[d] >= lo[d] && p[d] <= lo[d] + e.size_factor;
    if (!inside) continue;
    double value = 0;
    for (int local = 0; local < 8; ++local) {
      const std::array<int, 3>& q = mesh.LatticeOf(corner[local]);
      double weight = 1;
      for (int d = 0; d < 3; ++d) {
        const double t = static_cast<double>(p[d] - lo[d]) / e.size_factor;
        weight *= q[d] == lo[d] ? 1 - t : t;
      }
      value += weight * at_nodes[corner[local]];
    }
    return value;
  }
  ADD_FAILURE() << "no coarse element holds lattice point " << p[0] << ", " << p[1] << ", " << p[2];
  return 0;
}

TEST(StateTransfer, ALatticePointBetweenCoarseNodesTakesItsElementsField) {
  // A random state restored into a coarse configuration (each of its nodes takes its lattice
  // point's value) and captured again: every lattice point that is a node keeps its value, every
  // other one (inside a coarse cell, or a hanging node on its face) gets what the element around
  // it interpolates — including the cells at the object's far faces.
  const Scene coarse = testing::AdaptiveScene(2, 3, 600);
  AsyncRegions regions(coarse);
  const HybridMesh& mesh = regions.partition().mesh();
  const int n = coarse.mesh.nodes;
  ObjectState random;
  random.lattice_nodes = {n, n, n};
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> uniform(-1e-3, 1e-3);
  random.displacement_m.resize(static_cast<size_t>(3 * n * n * n));
  for (double& x : random.displacement_m) x = uniform(rng);
  random.velocity_m_per_s = random.displacement_m;
  // The supports stay fixed whatever the state says: zero there, as the regions keep them.
  for (const LatticeIndex& support : CubeSupportNodes(coarse.mesh)) {
    const size_t i = random.Index(support[0], support[1], support[2]);
    for (int c = 0; c < 3; ++c) random.displacement_m[i + c] = random.velocity_m_per_s[i + c] = 0;
  }
  regions.RestoreState(random);
  const ObjectState back = regions.CaptureState();
  std::vector<double> at_nodes(static_cast<size_t>(mesh.num_independent()));
  int interpolated = 0;
  double largest = 0;
  for (int c = 0; c < 3; ++c) {
    for (int node = 0; node < mesh.num_independent(); ++node) {
      const std::array<int, 3>& q = mesh.LatticeOf(node);
      at_nodes[node] = random.displacement_m[random.Index(q[0], q[1], q[2]) + c];
    }
    for (int ix = 0; ix < n; ++ix) {
      for (int iy = 0; iy < n; ++iy) {
        for (int iz = 0; iz < n; ++iz) {
          const size_t i = back.Index(ix, iy, iz) + c;
          double expected = random.displacement_m[i];
          if (mesh.IndependentAt(ix, iy, iz) < 0) {
            expected = ElementField(mesh, at_nodes, {ix, iy, iz});
            ++interpolated;
          }
          largest = std::max(largest, std::abs(back.displacement_m[i] - expected));
        }
      }
    }
  }
  EXPECT_GT(interpolated, 3 * 1000) << "the case is about points between coarse nodes";
  EXPECT_LT(largest, 1e-15);
}

TEST(StateTransfer, RefusesAStateOfAnotherLattice) {
  AsyncRegions regions(testing::AdaptiveScene(2, 2, 600));
  ObjectState other;
  other.lattice_nodes = {7, 7, 7};
  other.displacement_m.assign(3 * 7 * 7 * 7, 0.0);
  other.velocity_m_per_s = other.displacement_m;
  try {
    regions.RestoreState(other);
    FAIL() << "a state of 7 nodes per axis was taken by regions of 13";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("7 × 7 × 7 nodes"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("13"), std::string::npos) << e.what();
  }
}

// The paper's press (1 cm, 1 Hz) switched, at three moments, between multirate configurations
// of the default scene that differ in every parameter: the force must not step by more than
// 0.03 N between periods across the switch (a third of the 0.1 N a device port is held to).
TEST(StateTransfer, ASwitchBetweenMultirateConfigurationsInThePressDoesNotStepTheForce) {
  const long periods = 1000;
  const std::vector<std::pair<Scene, Scene>> switches = {
      {testing::AdaptiveScene(3, 2, 1000), testing::AdaptiveScene(2, 3, 600)},
      {testing::AdaptiveScene(2, 3, 600), testing::AdaptiveScene(4, 2, 800)},
      {testing::AdaptiveScene(1, 2, 700), testing::AdaptiveScene(3, 1, 1000)},
  };
  for (const auto& [from, to] : switches) {
    const std::vector<double> unswitched = PressWhole(from, periods);
    const double natural = LargestStep(unswitched, 0, unswitched.size());
    for (long switch_at : {250L, 500L, 730L}) {
      const std::vector<double> switched = PressSwitching(from, to, switch_at, periods);
      const double step = LargestStep(switched, switch_at - 5, switch_at + 50);
      std::printf(
          "switch r%d k%d %.0f Hz -> r%d k%d %.0f Hz at %ld ms: step %.4f N (unswitched "
          "largest %.4f N)\n",
          from.adaptivity.primary_size, from.adaptivity.secondary_lod,
          from.adaptivity.secondary_rate_hz, to.adaptivity.primary_size,
          to.adaptivity.secondary_lod, to.adaptivity.secondary_rate_hz, switch_at, step, natural);
      // Measured 0.008–0.017 N; the velocity carried at half its value gave 0.076 N, none 0.15 N.
      EXPECT_LE(step, 0.03) << "switched at " << switch_at << " ms";
    }
  }
}

}  // namespace
}  // namespace hapticsim
