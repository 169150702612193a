// ProxyContact at walls rising from its face, on a plain lattice (every node pushable, the state
// at rest, no compliance): the proxy stops at a wall's foot, whichever way its face looks, however
// far one slip would take it, and in a corner where two walls meet.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <array>
#include <functional>
#include <vector>

#include "core/trial/proxy_contact.hpp"

namespace hapticsim {
namespace {

constexpr double kH = 0.001;  // lattice spacing, m

// A lattice of nx × ny × 3 nodes whose voxel (x, y, z) the object fills where `filled` says.
ProxySurface Lattice(int nx, int ny, const std::function<bool(int, int, int)>& filled) {
  ProxySurface s;
  s.lattice_nodes = {nx, ny, 3};
  s.spacing_m = kH;
  for (int z = 0; z < 2; ++z) {
    for (int y = 0; y < ny - 1; ++y) {
      for (int x = 0; x < nx - 1; ++x) s.occupied.push_back(filled(x, y, z) ? 1 : 0);
    }
  }
  const int nodes = nx * ny * 3;
  for (int i = 0; i < nodes; ++i) s.dof.push_back(i);
  s.loadable.assign(static_cast<std::size_t>(nodes), 1);
  s.mass_kg.assign(static_cast<std::size_t>(nodes), 1e-3);
  s.component_stride = nodes;
  return s;
}

// A proxy on `surface` at `node` with the face's `inward` normal, touched at tool positions given
// in node spacings.
struct Touching {
  Touching(const ProxySurface& surface, const LatticeIndex& node,
           const std::array<double, 3>& inward, double static_mu, double kinetic_mu)
      : proxy(surface, node, inward, Settings(static_mu, kinetic_mu)),
        u(Eigen::VectorXd::Zero(3 * surface.num_nodes())),
        compliance(proxy.loaded_dofs().size(), 0.0),
        loads(proxy.loaded_dofs().size(), 0.0) {}
  static ContactSettings Settings(double static_mu, double kinetic_mu) {
    ContactSettings c;
    c.model = ContactModel::kProxy;
    c.static_friction = static_mu;
    c.kinetic_friction = kinetic_mu;
    return c;
  }
  ProxyContact::Result At(const std::array<double, 3>& tool) {
    return proxy.Update({tool[0] * kH, tool[1] * kH, tool[2] * kH}, u, compliance, loads);
  }
  double ProxyX() const { return proxy.proxy_rest_m()[0] / kH; }
  ProxyContact proxy;
  Eigen::VectorXd u;
  std::vector<double> compliance, loads;
};

// A ridge one voxel thick (x from 4 to 5) on the face z = 1 (inward +z), the tool 20 spacings deep
// and so far past it that one slip (μ_s 0.9 down to μ_k 0.1) would carry the proxy 14 spacings:
// it stops at the ridge's foot, held there, and does not tunnel through it.
TEST(ProxyWalls, ASlipLongerThanACellStopsAtAOneCellRidge) {
  const ProxySurface surface =
      Lattice(30, 6, [](int x, int, int z) { return z == 1 || (z == 0 && x == 4); });
  Touching touching(surface, {2, 2, 1}, {0, 0, 1}, 0.9, 0.1);
  touching.proxy.PlaceUnder({2 * kH, 2.5 * kH, 21 * kH});
  ProxyContact::Result last;
  for (int i = 0; i <= 400; ++i) {
    last = touching.At({2 + 0.05 * i, 2.5, 21});
    ASSERT_LE(touching.ProxyX(), 4.0) << "through the ridge at step " << i;
  }
  EXPECT_TRUE(last.in_contact);
  EXPECT_NEAR(touching.ProxyX(), 4.0, 1e-5) << "not at the ridge's foot";
  EXPECT_TRUE(last.wall_holds[0]) << "the ridge does not hold the pull along x";
  EXPECT_FALSE(last.wall_holds[1]);
}

// The face z = 1 looking the other way (inward −z: the object below it, z < 1), a wall at x from 2
// to 3 rising from it (towards +z): the proxy, pulled along −x, stops at x = 3, held there.
TEST(ProxyWalls, AWallOnAFaceLookingTheOtherWayHoldsToo) {
  const ProxySurface surface =
      Lattice(10, 6, [](int x, int, int z) { return z == 0 || (z == 1 && x == 2); });
  Touching touching(surface, {6, 2, 1}, {0, 0, -1}, 0.5, 0.4);
  touching.proxy.PlaceUnder({6 * kH, 2.5 * kH, 0.7 * kH});
  ProxyContact::Result last;
  for (int i = 0; i <= 100; ++i) last = touching.At({6 - 0.05 * i, 2.5, 0.7});
  EXPECT_TRUE(last.in_contact);
  EXPECT_NEAR(touching.ProxyX(), 3.0, 1e-5);
  EXPECT_TRUE(last.wall_holds[0]);
  EXPECT_LT(last.offset_m[0], -1.5 * kH) << "the tool 2 spacings past the wall's foot";
}

// Two walls meeting (x from 5 up, y from 4 up, on the face z = 1): a tool pulled diagonally into
// their corner leaves the proxy in it, held along both.
TEST(ProxyWalls, InACornerWhereTwoWallsMeetBothHold) {
  const ProxySurface surface =
      Lattice(10, 8, [](int x, int y, int z) { return z == 1 || (z == 0 && (x >= 5 || y >= 4)); });
  Touching touching(surface, {2, 1, 1}, {0, 0, 1}, 0.5, 0.4);
  touching.proxy.PlaceUnder({2 * kH, 1 * kH, 1.5 * kH});
  ProxyContact::Result last;
  for (int i = 0; i <= 200; ++i) last = touching.At({2 + 0.03 * i, 1 + 0.03 * i, 1.5});
  EXPECT_TRUE(last.in_contact);
  EXPECT_NEAR(touching.ProxyX(), 5.0, 1e-5);
  EXPECT_NEAR(touching.proxy.proxy_rest_m()[1] / kH, 4.0, 1e-5);
  EXPECT_TRUE(last.wall_holds[0]);
  EXPECT_TRUE(last.wall_holds[1]);
}

}  // namespace
}  // namespace hapticsim
