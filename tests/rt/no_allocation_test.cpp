// The time step runs in the 1 kHz thread: it must never touch the heap.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "core/fem/central_difference_integrator.hpp"
#include "core/fem/material_field.hpp"
#include "core/fem/stencil_stiffness.hpp"
#include "core/scene/contact_trajectory.hpp"
#include "core/scene/scene_model.hpp"
#include "tests/support/allocation_counter.hpp"
#include "tests/support/voxel_scene.hpp"

namespace hapticsim {
namespace {

TEST(AllocationCounter, SeesOperatorNewAndMalloc) {
  // The counter itself must be able to fail: a test that cannot fail proves nothing.
  testing::ScopedAllocationCount count;
  auto boxed = std::make_unique<std::vector<double>>(1000);
  void* volatile raw = std::malloc(64);  // volatile: the compiler may not elide the pair
  std::free(raw);
  EXPECT_GE(count.count(), 3u);
}

TEST(TimeStep, NeverAllocates) {
  const SceneModel cube(Scene{});
  CentralDifferenceIntegrator dut(cube.model(), cube.scene().solver.dt_s);
  const ContactTrajectory trajectory(cube.scene().input);
  std::array<double, 3> next{};
  testing::ScopedAllocationCount count;
  for (int n = 0; n < 500; ++n) {
    next[2] = trajectory.DepthAt((n + 1) * 1e-3);
    ASSERT_EQ(dut.Step(next), StepStatus::kOk);
  }
  EXPECT_EQ(count.count(), 0u);
}

}  // namespace
}  // namespace hapticsim

#include "core/regions/async_regions.hpp"

namespace hapticsim {
namespace {

TEST(RegionSteps, NeverAllocate) {
  for (bool displacement_coupling : {true, false}) {
    Scene scene;
    scene.adaptivity.primary_size = 2;
    scene.adaptivity.secondary_regions = 2;
    scene.adaptivity.displacement_coupling = displacement_coupling;
    AsyncRegions dut(scene);
    std::array<double, 3> contact{0, 0, 0};
    testing::ScopedAllocationCount count;
    std::uint64_t request = 0;
    for (int n = 0; n < 200; ++n) {
      // Half the steps publish the surface too (a reader asks before each: hapticsimd asks at
      // its visual rate).
      if (n % 2 == 0) request = dut.RequestSurface();
      dut.AdvanceSecondariesTo(dut.state_ticks(kPrimaryRegion) + dut.period_ticks(kPrimaryRegion));
      contact[2] = 1e-5 * n;
      const auto reaction = dut.StepPrimary(contact);
      ASSERT_TRUE(std::isfinite(reaction[2]));
    }
    EXPECT_EQ(count.count(), 0u) << (displacement_coupling ? "displacement" : "force");
    EXPECT_TRUE(dut.SurfaceServed(request - 1)) << "the steps never published the surface";
  }
}

// The same while the port limits act: the force exchange (where they act too) on a configuration
// whose exchange grows (ν 0.49, k 1 r 2 at 900 Hz) from a random state (every mode excited),
// stepped until they have refused work.
TEST(RegionSteps, NeverAllocateWhileThePortLimitsAct) {
  Scene scene;
  scene.material.poisson_ratio = 0.49;
  scene.adaptivity.primary_size = 2;
  scene.adaptivity.secondary_lod = 1;
  scene.adaptivity.secondary_rate_hz = 900;
  scene.adaptivity.displacement_coupling = false;
  AsyncRegions dut(scene);
  dut.SetRandomState(5);
  std::array<double, 3> contact{0, 0, 0};
  testing::ScopedAllocationCount count;
  for (int n = 0; n < 1000; ++n) {
    dut.AdvanceSecondariesTo(dut.state_ticks(kPrimaryRegion) + dut.period_ticks(kPrimaryRegion));
    contact[2] = 2e-5 * n;
    ASSERT_TRUE(std::isfinite(dut.StepPrimary(contact)[2]));
  }
  EXPECT_EQ(count.count(), 0u);
  EXPECT_GT(dut.Energies().port_refused_j, 0) << "the limits never acted: the test saw nothing";
}

}  // namespace
}  // namespace hapticsim

#include "core/errormap/error_lookup.hpp"
#include "core/errormap/sweep_grid.hpp"

namespace hapticsim {
namespace {

// The error lookup may run in the 1 kHz thread: point queries, box queries and the frequency
// bound, on a map the size of the paper's grid.
TEST(ErrorLookup, NeverAllocates) {
  const SweepGrid paper = PaperGrid(PointOfScene(Scene{}));
  ErrorMap map = ErrorMap::MakeGrid(paper.axes);
  for (size_t i = 0; i < map.samples.size(); ++i) {
    map.samples[i].status = SampleStatus::kOk;
    map.samples[i].max_magnitude_percent = static_cast<double>(i % 97) / 10;
  }
  const ErrorLookup lookup(map, ErrorField::kMagnitude);
  LookupQuery query = LookupQuery::At(map.samples[12345].point);
  query.hi[0] = 0.48;  // a neighbourhood of heterogeneous material
  query.lo[3] = 6000, query.hi[3] = 17000;
  query.frequency_known = false;
  double sum = 0;
  testing::ScopedAllocationCount count;
  for (int n = 0; n < 1000; ++n) {
    query.lo[8] = 600 + n % 400;
    query.hi[8] = query.lo[8];
    sum += lookup.Lookup(query).error;
  }
  EXPECT_EQ(count.count(), 0u);
  EXPECT_GT(sum, 0);
}

}  // namespace
}  // namespace hapticsim

#include "daemon/haptic_loop.hpp"
#include "daemon/port_guard.hpp"

namespace hapticsim {
namespace {

// hapticsimd's primary period (input slot → contact → step → force ring) on the default
// configuration, in and out of contact, asleep and woken, with stale input: never touches the
// heap.
TEST(DaemonPrimaryPeriod, NeverAllocates) {
  Scene scene;
  scene.adaptivity.primary_size = 3;
  HapticLoop loop(scene, HapticLoop::Options{});
  std::int64_t now = HapticLoop::NowNs();
  ForceRecord record;
  int forces = 0;
  bool pushed_back = false;
  testing::ScopedAllocationCount count;
  for (int n = 0; n < 600; ++n, now += 1'000'000) {
    if (n < 400) {
      const double z = n < 100 ? -0.002 : 0.01 * (n - 100) / 300.0;
      loop.OfferInput(DeviceSample{n, now, {0.125, 0.125, z}, false});
    }  // then the input goes stale
    loop.PrimaryPeriod(now, now);
    for (int r = 1; r < loop.regions().num_regions(); ++r) {
      if (loop.SecondaryMayStep(r)) const_cast<AsyncRegions&>(loop.regions()).StepRegion(r);
    }
    while (loop.forces().Pop(&record)) {
      ++forces;
      pushed_back |= record.force_n[2] < -0.1;
    }
  }
  EXPECT_EQ(count.count(), 0u);
  EXPECT_EQ(forces, 600);
  EXPECT_EQ(loop.sleeps(), 1) << "asleep above the surface, woken by the touch (sleeping and "
                                 "waking are covered too)";
  EXPECT_TRUE(pushed_back);
  EXPECT_TRUE(record.flags & force_flags::kInputStale);
}

// A sliding tool (contact.model = "proxy") in the primary period: touching down, pressing,
// sticking, sliding 70 mm across the face and out of the primary region it is bound to (nothing
// moves the regions here: the proxy leaves them and asks them to follow), then lifting off.
TEST(DaemonPrimaryPeriod, NeverAllocatesWithASlidingTool) {
  Scene scene;
  scene.adaptivity.primary_size = 3;
  scene.contact.model = ContactModel::kProxy;
  HapticLoop loop(scene, HapticLoop::Options{});
  std::int64_t now = HapticLoop::NowNs();
  ForceRecord record;
  std::int32_t flags = 0;
  double largest_lateral = 0;
  testing::ScopedAllocationCount count;
  for (int n = 0; n < 1200; ++n, now += 1'000'000) {
    const double z = n < 100    ? -0.002
                     : n < 1100 ? std::min(0.005, 0.005 * (n - 100) / 200.0)
                                : -0.002;
    const double x = 0.125 + (n < 300 ? 0.0 : 0.07 * std::min(1.0, (n - 300) / 700.0));
    loop.OfferInput(DeviceSample{n, now, {x, 0.125, z}, false});
    loop.PrimaryPeriod(now, now);
    for (int r = 1; r < loop.regions().num_regions(); ++r) {
      if (loop.SecondaryMayStep(r)) const_cast<AsyncRegions&>(loop.regions()).StepRegion(r);
    }
    while (loop.forces().Pop(&record)) {
      flags |= record.flags;
      largest_lateral = std::max(largest_lateral, std::abs(record.force_n[0]));
    }
    if (loop.contact_following()) flags |= 1 << 30;
  }
  EXPECT_EQ(count.count(), 0u);
  EXPECT_TRUE(flags & force_flags::kInContact);
  EXPECT_GT(largest_lateral, 0.1) << "it pulled and slid";
  EXPECT_TRUE(flags & (1 << 30)) << "it asked the regions to follow";
  EXPECT_TRUE(flags & force_flags::kReconfiguring) << "it slid out of the regions and waited";
}

// An object that leaves voxels empty (ContactObject on voxels): the block of 10 × 6 × 4 voxels of
// 1 cm with a step cut out of its front (x < 4 cm, z < 2 cm empty), its back held. The tool hovers
// in the step and in front of the object (the hovered face, the nearest voxel), presses into the
// step's floor (the way in through the voxels), drags along it 6 mm past the wall (the proxy held
// at its foot), lifts off and
// presses the front face beside the step: with the node contact, then with a sliding tool (the
// flat faces, the node inside the face, the proxy on the floor).
TEST(DaemonPrimaryPeriod, NeverAllocatesOnAnObjectWithEmptyVoxels) {
  Scene scene =
      testing::VoxelScene(10, 6, 4, 0.01, [](int x, int, int z) { return x < 4 && z < 2 ? 0 : 1; });
  testing::HoldPlaneZ(&scene, 0.04);
  scene.materials = {{1, Material{}}};
  scene.adaptivity.primary_size = 3;
  scene.adaptivity.secondary_lod = 1;
  scene.adaptivity.secondary_rate_hz = 1000;
  scene.input.contact_node = LatticeIndex{2, 3, 2};
  for (const ContactModel model : {ContactModel::kNode, ContactModel::kProxy}) {
    scene.contact.model = model;
    HapticLoop loop(scene, HapticLoop::Options{});
    std::int64_t now = HapticLoop::NowNs();
    ForceRecord record;
    bool pushed_back = false;
    testing::ScopedAllocationCount count;
    for (int n = 0; n < 1000; ++n, now += 1'000'000) {
      std::array<double, 3> tip{0.02, 0.03, 0.015};  // hovering in the step
      if (n < 50) {
        tip = {0.02, 0.03, -0.01};  // in front of it
      } else if (n < 400) {
        tip[2] = 0.018 + 0.007 * std::min(1.0, (n - 100) / 200.0);  // into the floor
      } else if (n < 500) {
        tip = {0.02 + 0.026 * (n - 400) / 100.0, 0.03, 0.025};  // along it, 6 mm past the wall
      } else if (n < 700) {
        tip = {0.06, 0.03, -0.002};  // lifted, over the front face
      } else {
        tip = {0.06, 0.03, 0.003 * (n - 700) / 300.0};  // pressing it
      }
      loop.OfferInput(DeviceSample{n, now, tip, false});
      loop.PrimaryPeriod(now, now);
      for (int r = 1; r < loop.regions().num_regions(); ++r) {
        if (loop.SecondaryMayStep(r)) const_cast<AsyncRegions&>(loop.regions()).StepRegion(r);
      }
      while (loop.forces().Pop(&record)) pushed_back |= record.force_n[2] < -0.05;
    }
    const char* name = model == ContactModel::kNode ? "node contact" : "sliding tool";
    EXPECT_EQ(count.count(), 0u) << name;
    EXPECT_TRUE(pushed_back) << name << ": the floor pushed back";
    EXPECT_EQ(loop.wanted_contact_node(), (LatticeIndex{6, 3, 0}))
        << name << ": the front face beside the step";
  }
}

// The port guard acting in the primary period: the envelope saturating, the engagement ramp and a
// fault latching (a fault_force_n below the press's force) cost no allocation either. (Its
// passivity controller dissipating: PortGuardPeriod.NeverAllocatesWhileDissipating, below.)
TEST(DaemonPrimaryPeriod, NeverAllocatesWhileThePortGuardActs) {
  Scene scene;
  scene.adaptivity.primary_size = 3;
  HapticLoop::Options options;
  options.port.max_force_n = 0.3;
  options.port.fault_force_n = 0.6;
  HapticLoop loop(scene, options);
  std::int64_t now = HapticLoop::NowNs();
  ForceRecord record;
  std::int32_t flags = 0;
  testing::ScopedAllocationCount count;
  for (int n = 0; n < 500; ++n, now += 1'000'000) {
    // In 1 cm, out again (the passivity controller watches the way out), in again.
    const double z = n < 20 ? -0.002 : 0.01 * std::sin(3.14159 * (n - 20) / 240.0);
    loop.OfferInput(DeviceSample{n, now, {0.125, 0.125, z}, false});
    loop.PrimaryPeriod(now, now);
    for (int r = 1; r < loop.regions().num_regions(); ++r) {
      if (loop.SecondaryMayStep(r)) const_cast<AsyncRegions&>(loop.regions()).StepRegion(r);
    }
    while (loop.forces().Pop(&record)) flags |= record.flags;
  }
  EXPECT_EQ(count.count(), 0u);
  EXPECT_TRUE(flags & force_flags::kForceLimited);
  EXPECT_EQ(loop.force_faults(), 1);
  EXPECT_TRUE(flags & force_flags::kFaultLatched);
}

// The port guard on its own while its passivity controller acts (an active environment: a
// negative damper) and its envelope limits: no allocation either.
TEST(PortGuardPeriod, NeverAllocatesWhileDissipating) {
  PortGuardSettings settings;
  settings.max_force_n = 1.0;
  PortGuard guard(settings, 1e-3);
  PortGuard::Input in;
  in.render = in.engaged = in.have_position = true;
  in.inward_normal = {0, 0, 1};
  int dissipating = 0, limited = 0;
  double previous_z = 0;
  testing::ScopedAllocationCount count;
  for (int n = 0; n < 2000; ++n) {
    const double z = 0.005 * (1 - std::cos(2 * 3.141592653589793 * n / 1000.0));
    in.now_ns = (n + 1) * 1'000'000;
    in.position_m = {0.1, 0.1, z};
    in.simulated_n = {0, 0, -150 * z + 20 * (z - previous_z) / 1e-3};
    previous_z = z;
    const PortGuard::Output out = guard.Period(in);
    dissipating += out.dissipating;
    limited += out.limited;
  }
  EXPECT_EQ(count.count(), 0u);
  EXPECT_GT(dissipating, 0);
  EXPECT_GT(limited, 0);
}

// Any shape and several materials: the time step on the element-by-element operator, an L of
// two materials held on its back face and pressed on its front.
TEST(TimeStepOnAnyShape, NeverAllocates) {
  const HexGrid grid(7, 7, 4, 0.02);
  Material stiff;
  stiff.youngs_modulus_pa *= 8;
  stiff.damping_per_s = 25;  // another damping than the soft one's: per-DOF rates
  std::vector<std::int16_t> elements(static_cast<size_t>(grid.num_elements()));
  for (int e = 0; e < grid.num_elements(); ++e) {
    const int ex = e % 6, ey = (e / 6) % 6;
    elements[static_cast<size_t>(e)] = ex >= 3 && ey >= 3 ? -1 : static_cast<std::int16_t>(ex < 2);
  }
  DofConstraints constraints;
  for (int ix = 0; ix < 3; ++ix) {
    for (int c = 0; c < 3; ++c) constraints.fixed_dofs.push_back(grid.Dof(grid.Node(ix, 0, 3), c));
  }
  for (int c = 0; c < 3; ++c) constraints.driven_dofs.push_back(grid.Dof(grid.Node(1, 1, 0), c));
  const ElasticModel model(grid, MaterialField(grid, {Material{}, stiff}, elements), constraints);
  ASSERT_EQ(dynamic_cast<const StencilStiffness*>(&model.stiffness()), nullptr);
  CentralDifferenceIntegrator dut(model, 1e-4);
  std::array<double, 3> next{};
  testing::ScopedAllocationCount count;
  for (int n = 0; n < 500; ++n) {
    next[2] = 1e-6 * n;
    ASSERT_EQ(dut.Step(next), StepStatus::kOk);
  }
  EXPECT_EQ(count.count(), 0u);
}

}  // namespace
}  // namespace hapticsim
