// The object's surface as the regions publish it for drawing (AsyncRegions::RequestSurface,
// SurfaceServed, ReadSurface). Checked against what is independent of the publication: a linear
// displacement field is reproduced exactly by every field the mesh can hold (trilinear cells
// and independent nodes alike), the contact point is where the press put it, and what the
// regions publish while they step is what the whole state (CaptureState) holds.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <vector>

#include "core/regions/async_regions.hpp"
#include "core/scene/contact_trajectory.hpp"
#include "tests/support/adaptive_scene.hpp"

namespace hapticsim {
namespace {

std::array<int, 3> LatticeOfId(std::int32_t id, int n) {
  return {id / (n * n), id / n % n, id % n};
}

bool IsSupport(const std::array<int, 3>& p, int n) {
  for (const LatticeIndex& s : CubeSupportNodes(MeshSettings{n, 0.25})) {
    // A point within a coarse cell of a support may take part of its (zero) value.
    if (std::abs(p[0] - s[0]) < 4 && std::abs(p[1] - s[1]) < 4 && std::abs(p[2] - s[2]) < 4) {
      return true;
    }
  }
  return false;
}

Scene TwoShells() {
  Scene scene = testing::AdaptiveScene(2, 2, 500);
  scene.adaptivity.secondary_regions = 2;
  scene.adaptivity.outer_rate_hz = 250;
  return scene;
}

TEST(RegionSurface, IsEveryPointOnTheCubesFacesOnce) {
  const AsyncRegions regions(TwoShells());
  const int n = regions.partition().mesh().options().lattice_nodes[0];
  const std::vector<std::int32_t>& ids = regions.surface_ids();
  EXPECT_EQ(ids.size(), static_cast<size_t>(n * n * n - (n - 2) * (n - 2) * (n - 2)));
  for (size_t i = 0; i < ids.size(); ++i) {
    if (i > 0) {
      ASSERT_LT(ids[i - 1], ids[i]);
    }
    const auto p = LatticeOfId(ids[i], n);
    const bool on_face =
        p[0] == 0 || p[1] == 0 || p[2] == 0 || p[0] == n - 1 || p[1] == n - 1 || p[2] == n - 1;
    ASSERT_TRUE(on_face) << ids[i];
  }
}

// u(x) = A·x + b on every lattice point: every point of the surface away from the supports
// (which stay at zero) reads back exactly that, through independent nodes and coarse cells alike.
TEST(RegionSurface, ReproducesALinearFieldExactly) {
  for (const Scene& scene : {TwoShells(), testing::AdaptiveScene(3, 3, 1000)}) {
    AsyncRegions regions(scene);
    const int n = regions.partition().mesh().options().lattice_nodes[0];
    const double A[3][3] = {{1e-3, 2e-4, -3e-4}, {-1e-4, 5e-4, 7e-4}, {2e-4, -6e-4, 9e-4}};
    const double b[3] = {1e-4, -2e-4, 3e-5};
    auto field = [&](const std::array<int, 3>& p, int c) {
      return A[c][0] * p[0] + A[c][1] * p[1] + A[c][2] * p[2] + b[c];
    };
    ObjectState state;
    state.lattice_nodes = {n, n, n};
    state.displacement_m.assign(static_cast<size_t>(3) * n * n * n, 0.0);
    state.velocity_m_per_s.assign(state.displacement_m.size(), 0.0);
    for (int ix = 0; ix < n; ++ix) {
      for (int iy = 0; iy < n; ++iy) {
        for (int iz = 0; iz < n; ++iz) {
          for (int c = 0; c < 3; ++c)
            state.displacement_m[state.Index(ix, iy, iz) + c] = field({ix, iy, iz}, c);
        }
      }
    }
    regions.RestoreState(state);
    std::vector<double> surface;
    ASSERT_TRUE(regions.ReadSurface(&surface));
    ASSERT_EQ(surface.size(), 3 * regions.surface_ids().size());
    int checked = 0;
    for (size_t i = 0; i < regions.surface_ids().size(); ++i) {
      const auto p = LatticeOfId(regions.surface_ids()[i], n);
      if (IsSupport(p, n)) continue;
      for (int c = 0; c < 3; ++c) ASSERT_NEAR(surface[3 * i + c], field(p, c), 1e-15) << i;
      ++checked;
    }
    EXPECT_GT(checked, static_cast<int>(regions.surface_ids().size()) * 8 / 10);
  }
}

// A press on the virtual-time schedule: a request is served by every region's next step and not
// before; asked before every step, the published surface is the whole state's (CaptureState) to
// the last bit, and the contact point is exactly where the press put it.
TEST(RegionSurface, IsPublishedByTheNextStepOfEveryRegionWhenAsked) {
  const Scene scene = TwoShells();
  AsyncRegions regions(scene);
  const LatticeIndex node = ContactNode(scene);
  const ContactTrajectory trajectory(scene.input, InwardNormal(scene.mesh, node));
  const int n = scene.mesh.nodes;
  auto press = [&](long periods, bool ask_every_step) {
    std::array<double, 3> contact{};
    for (long k = 0; k < periods; ++k) {
      if (ask_every_step) regions.RequestSurface();
      const std::int64_t next =
          regions.state_ticks(kPrimaryRegion) + regions.period_ticks(kPrimaryRegion);
      regions.AdvanceSecondariesTo(next);
      contact = trajectory.DisplacementAt(static_cast<double>(next) / regions.ticks_per_second());
      regions.StepPrimary(contact);
    }
    return contact;
  };
  std::vector<std::uint64_t> at_rest;
  for (int a = 0; a < regions.num_regions(); ++a) {
    at_rest.push_back(regions.surface_publications(a));
    EXPECT_GE(at_rest.back(), 1u) << "the constructor's Reset publishes every part";
  }
  press(250, false);
  for (int a = 0; a < regions.num_regions(); ++a) {
    EXPECT_EQ(regions.surface_publications(a), at_rest[a])
        << "region " << a << " published unasked";
  }
  const std::uint64_t request = regions.RequestSurface();
  EXPECT_FALSE(regions.SurfaceServed(request)) << "served before any region stepped";
  // Every region steps within the slowest one's period (4 ms at 250 Hz).
  const std::array<double, 3> contact = press(6, true);
  ASSERT_TRUE(regions.SurfaceServed(request));
  for (int a = 0; a < regions.num_regions(); ++a) {
    EXPECT_GT(regions.surface_publications(a), at_rest[a]) << "region " << a;
  }
  std::vector<double> surface;
  ASSERT_TRUE(regions.ReadSurface(&surface));
  const ObjectState state = regions.CaptureState();

  const std::int32_t contact_id = (node[0] * n + node[1]) * n + node[2];
  const auto& ids = regions.surface_ids();
  bool found = false;
  double largest = 0;
  for (size_t i = 0; i < ids.size(); ++i) {
    const auto p = LatticeOfId(ids[i], n);
    const auto whole = state.DisplacementAt(p[0], p[1], p[2]);
    for (int c = 0; c < 3; ++c) {
      ASSERT_EQ(surface[3 * i + c], whole[c]) << "point " << ids[i] << " component " << c;
      largest = std::max(largest, std::abs(surface[3 * i + c]));
    }
    if (ids[i] == contact_id) {
      found = true;
      for (int c = 0; c < 3; ++c) EXPECT_EQ(surface[3 * i + c], contact[c]) << c;
    }
  }
  EXPECT_TRUE(found);
  EXPECT_GT(largest, 3e-3) << "the press had not gone in: the test saw nothing";
}

}  // namespace
}  // namespace hapticsim
