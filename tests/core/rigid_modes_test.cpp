// Whether a scene's supports remove every rigid-body mode (RigidBodyModeProblem), checked against
// the definition: the stiffness matrix restricted to the free degrees of freedom has a zero
// eigenvalue exactly when the object can move without straining. The oracle assembles K for small
// shapes and computes its smallest eigenvalue; the check under test only counts held nodes.
#include "core/fem/rigid_modes.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <functional>
#include <vector>

#include "core/fem/assembled_stiffness.hpp"

namespace hapticsim {
namespace {

MaterialField Shape(const HexGrid& grid, const std::function<bool(int, int, int)>& inside) {
  std::vector<std::int16_t> elements(static_cast<std::size_t>(grid.num_elements()),
                                     MaterialField::kEmpty);
  for (int z = 0; z + 1 < grid.nz(); ++z) {
    for (int y = 0; y + 1 < grid.ny(); ++y) {
      for (int x = 0; x + 1 < grid.nx(); ++x) {
        if (inside(x, y, z)) {
          elements[static_cast<std::size_t>(x + (grid.nx() - 1) * (y + (grid.ny() - 1) * z))] = 0;
        }
      }
    }
  }
  return MaterialField(grid, {Material{}}, elements);
}

// The smallest eigenvalue of K over the DOFs of the object's nodes that are not fixed, relative
// to the largest: ~1e-16 with a rigid-body mode left, ≫ 1e-10 without.
double SmallestRelativeEigenvalue(const HexGrid& grid, const MaterialField& field,
                                  const std::vector<int>& fixed) {
  const Eigen::MatrixXd k = Eigen::MatrixXd(AssembledStiffness(grid, field).matrix());
  const std::vector<bool> active = field.ActiveNodes(grid);
  std::vector<int> free_dofs;
  for (int node = 0; node < grid.num_nodes(); ++node) {
    const bool is_fixed = std::find(fixed.begin(), fixed.end(), node) != fixed.end();
    if (!active[static_cast<std::size_t>(node)] || is_fixed) continue;
    for (int c = 0; c < 3; ++c) free_dofs.push_back(grid.Dof(node, c));
  }
  const int n = static_cast<int>(free_dofs.size());
  Eigen::MatrixXd reduced(n, n);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) reduced(i, j) = k(free_dofs[i], free_dofs[j]);
  }
  const Eigen::VectorXd eigenvalues =
      Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(reduced, Eigen::EigenvaluesOnly)
          .eigenvalues();
  return eigenvalues.minCoeff() / eigenvalues.maxCoeff();
}

struct Case {
  const char* name;
  HexGrid grid;
  std::function<bool(int, int, int)> inside;
  std::vector<std::array<int, 3>> fixed;
  bool expect_held;
};

std::vector<Case> Cases() {
  const auto all = [](int, int, int) { return true; };
  // Two 1-element-thick blocks joined along one edge only: x < 2 at z = 0, x ≥ 2 at z = 1.
  const auto hinged = [](int x, int, int z) { return (x < 2) == (z == 0); };
  // Two blocks that touch nowhere.
  const auto apart = [](int x, int, int) { return x != 2; };
  // An L: the upper-right quarter in x and y removed.
  const auto ell = [](int x, int y, int) { return x < 2 || y < 2; };
  return {
      {"the cube at its four back corners", HexGrid(3, 3, 3, 0.1), all,
       {{0, 0, 2}, {2, 0, 2}, {0, 2, 2}, {2, 2, 2}}, true},
      {"the cube at three corners", HexGrid(3, 3, 3, 0.1), all,
       {{0, 0, 2}, {2, 0, 2}, {0, 2, 2}}, true},
      {"the cube at two corners (it turns about their line)", HexGrid(3, 3, 3, 0.1), all,
       {{0, 0, 2}, {2, 2, 2}}, false},
      {"the cube at three nodes on one line", HexGrid(3, 3, 3, 0.1), all,
       {{0, 0, 2}, {1, 0, 2}, {2, 0, 2}}, false},
      {"an L held at the end of one arm", HexGrid(4, 4, 2, 0.1), ell,
       {{0, 3, 0}, {1, 3, 0}, {0, 3, 1}}, true},
      {"two blocks on a hinge, one held", HexGrid(5, 2, 3, 0.1), hinged,
       {{0, 0, 0}, {0, 1, 0}, {0, 0, 1}}, false},
      {"two blocks on a hinge, each held at one more node", HexGrid(5, 2, 3, 0.1), hinged,
       {{0, 0, 0}, {0, 1, 0}, {0, 0, 1}, {4, 0, 2}}, true},
      {"two separate blocks, one held", HexGrid(6, 2, 2, 0.1), apart,
       {{0, 0, 0}, {0, 1, 0}, {0, 0, 1}}, false},
      {"two separate blocks, both held", HexGrid(6, 2, 2, 0.1), apart,
       {{0, 0, 0}, {0, 1, 0}, {0, 0, 1}, {5, 0, 0}, {5, 1, 0}, {5, 0, 1}}, true},
  };
}

TEST(RigidBodyModes, TheCheckAgreesWithTheSmallestEigenvalueOfTheHeldStiffness) {
  for (const Case& c : Cases()) {
    SCOPED_TRACE(c.name);
    const MaterialField field = Shape(c.grid, c.inside);
    std::vector<int> fixed;
    for (const auto& at : c.fixed) fixed.push_back(c.grid.Node(at[0], at[1], at[2]));
    const double smallest = SmallestRelativeEigenvalue(c.grid, field, fixed);
    // The oracle first: the case must be what its name says.
    if (c.expect_held) {
      EXPECT_GT(smallest, 1e-8);
    } else {
      EXPECT_LT(smallest, 1e-12);
    }
    const std::string problem = RigidBodyModeProblem(c.grid, field, fixed);
    EXPECT_EQ(problem.empty(), c.expect_held) << problem;
  }
}

TEST(RigidBodyModes, TheMessageSaysWhichPartIsFreeAndWhatToDo) {
  const HexGrid grid(6, 2, 2, 0.1);
  const MaterialField field = Shape(grid, [](int x, int, int) { return x != 2; });
  const std::string problem = RigidBodyModeProblem(
      grid, field, {grid.Node(0, 0, 0), grid.Node(0, 1, 0), grid.Node(0, 0, 1)});
  // The free block is elements x = 3, 4: its nodes' centre is at x = 0.4 m.
  EXPECT_NE(problem.find("2 elements around (0.4, 0.05, 0.05) m"), std::string::npos) << problem;
  EXPECT_NE(problem.find("held at 0 nodes"), std::string::npos) << problem;
  EXPECT_NE(problem.find("three of its nodes that are not on one line"), std::string::npos);
}

}  // namespace
}  // namespace hapticsim
