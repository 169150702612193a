// The asynchronous regions on an object that is not the cube: a block with a notch cut out of one
// edge, of two materials (an inclusion denser, stiffer and more damped than the tissue), on a
// lattice whose node intervals the coarse factor does not divide. Checked against what does not
// depend on the hybrid mesh: the voxels' own volume and mass, the rigid-body modes, the fine
// grid's operator (ElasticModel's, a separate implementation) at coarse factor 1, and the
// full-resolution reference run of the same scene.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>
#include <cstdio>
#include <cstdint>
#include <vector>

#include "core/error.hpp"
#include "core/fem/elastic_model.hpp"
#include "core/fem/hex_grid.hpp"
#include "core/fem/material_field.hpp"
#include "core/regions/async_regions.hpp"
#include "core/regions/box_stiffness.hpp"
#include "core/regions/element_set_stiffness.hpp"
#include "core/regions/hybrid_mesh.hpp"
#include "core/scene/scene_model.hpp"
#include "core/trial/force_error.hpp"
#include "core/trial/reference_trial.hpp"
#include "tests/support/hybrid_mesh_fields.hpp"
#include "tests/support/voxel_scene.hpp"

namespace hapticsim {
namespace {

constexpr double kH = 0.01;                      // voxel edge, m
constexpr std::array<int, 3> kVoxels{11, 9, 10};  // 11 and 9 intervals: k = 2 does not divide

// 0 in the notch (an edge cut away through z), 2 in the inclusion, 1 elsewhere.
int NotchedBlockLabel(int x, int y, int z) {
  if (x >= 8 && y >= 6) return 0;
  const bool inclusion = x >= 3 && x < 7 && y >= 2 && y < 6 && z >= 2 && z < 6;
  return inclusion ? 2 : 1;
}

std::vector<Material> TwoMaterials() {
  Material tissue, inclusion;
  tissue.damping_per_s = 2;
  inclusion.youngs_modulus_pa = 5 * tissue.youngs_modulus_pa;
  inclusion.density_kg_m3 = 1500;
  inclusion.damping_per_s = 6;
  return {tissue, inclusion};
}

// Per fine cell (x fastest), the material index or −1 (MaterialField's order).
std::vector<std::int16_t> CellMaterials() {
  std::vector<std::int16_t> cells;
  for (int z = 0; z < kVoxels[2]; ++z)
    for (int y = 0; y < kVoxels[1]; ++y)
      for (int x = 0; x < kVoxels[0]; ++x)
        cells.push_back(static_cast<std::int16_t>(NotchedBlockLabel(x, y, z) - 1));
  return cells;
}

// The back face's nodes that an occupied voxel touches: held.
std::vector<std::array<int, 3>> BackFace() {
  std::vector<std::array<int, 3>> held;
  for (int iy = 0; iy <= kVoxels[1]; ++iy)
    for (int ix = 0; ix <= kVoxels[0]; ++ix) {
      bool touched = false;
      for (int x : {ix - 1, ix})
        for (int y : {iy - 1, iy})
          touched = touched || (x >= 0 && y >= 0 && x < kVoxels[0] && y < kVoxels[1] &&
                                NotchedBlockLabel(x, y, kVoxels[2] - 1) > 0);
      if (touched) held.push_back({ix, iy, kVoxels[2]});
    }
  return held;
}

HybridMesh::Options NotchedOptions(int k) {
  HybridMesh::Options o;
  o.lattice_nodes = {kVoxels[0] + 1, kVoxels[1] + 1, kVoxels[2] + 1};
  o.spacing_m = kH;
  o.coarse_factor = k;
  o.cell_material = CellMaterials();
  o.primary_lo = {3, 2, 0};
  o.primary_hi = {7, 6, 2};
  o.supports = BackFace();
  return o;
}

using testing::AffineField;
using testing::AllElements;

TEST(HybridMeshOnAnObject, CoversEveryOccupiedVoxelOnceAndKeepsItsMass) {
  const std::vector<std::int16_t> cells = CellMaterials();
  const std::vector<Material> materials = TwoMaterials();
  double voxel_mass = 0;
  int occupied = 0;
  for (std::int16_t m : cells) {
    if (m < 0) continue;
    ++occupied;
    voxel_mass += materials[m].density_kg_m3 * kH * kH * kH;
  }
  for (int k : {2, 3}) {
    const HybridMesh mesh(NotchedOptions(k));
    int coarse = 0, covered = 0;
    for (const HybridElement& e : mesh.elements()) {
      coarse += e.size_factor > 1;
      covered += e.size_factor * e.size_factor * e.size_factor;
    }
    EXPECT_GT(coarse, 0) << "k = " << k;
    EXPECT_GT(mesh.num_hanging(), 0) << "k = " << k;
    // Every occupied voxel covered, nothing else, and the elements' volumes add up to exactly
    // the voxels': so no voxel twice.
    const std::vector<RegionIndex> region = mesh.RegionPerLatticeCell();
    for (int z = 0; z < kVoxels[2]; ++z)
      for (int y = 0; y < kVoxels[1]; ++y)
        for (int x = 0; x < kVoxels[0]; ++x) {
          const size_t cell = (static_cast<size_t>(x) * kVoxels[1] + y) * kVoxels[2] + z;
          EXPECT_EQ(region[cell] >= 0, NotchedBlockLabel(x, y, z) > 0)
              << "k = " << k << ", voxel " << x << ", " << y << ", " << z;
        }
    EXPECT_EQ(covered, occupied) << "k = " << k;
    // The inclusion is 1.5× denser: a coarse element across the boundary would miscount.
    EXPECT_NEAR(mesh.DofMass(materials).head(mesh.num_independent()).sum(), voxel_mass,
                1e-12 * voxel_mass)
        << "k = " << k;
  }
}

TEST(HybridMeshOnAnObject, RigidMotionsCostNoForceAndAStretchDoes) {
  for (int k : {2, 3}) {
    const HybridMesh mesh(NotchedOptions(k));
    const ElementSetStiffness stiffness(mesh, TwoMaterials(), AllElements(mesh));
    Eigen::VectorXd ku(mesh.num_dofs());
    Eigen::Matrix3d stretch = Eigen::Matrix3d::Zero();
    stretch(0, 0) = 1e-3;
    stiffness.Apply(AffineField(mesh, stretch, Eigen::Vector3d::Zero()), ku);
    const double stretched = ku.norm();
    ASSERT_GT(stretched, 0);
    for (int axis = 0; axis < 3; ++axis) {
      Eigen::Vector3d shift = Eigen::Vector3d::Zero();
      shift[axis] = 1e-3 * kH * kVoxels[0];
      stiffness.Apply(AffineField(mesh, Eigen::Matrix3d::Zero(), shift), ku);
      EXPECT_LT(ku.norm(), 1e-12 * stretched) << "translation " << axis << ", k = " << k;
      // A small rotation about the axis: u = ω × x, the same size as the stretch.
      Eigen::Matrix3d spin = Eigen::Matrix3d::Zero();
      const int b = (axis + 1) % 3, c = (axis + 2) % 3;
      spin(b, c) = -1e-3;
      spin(c, b) = 1e-3;
      stiffness.Apply(AffineField(mesh, spin, Eigen::Vector3d::Zero()), ku);
      EXPECT_LT(ku.norm(), 1e-12 * stretched) << "rotation " << axis << ", k = " << k;
    }
  }
}

TEST(HybridMeshOnAnObject, AtFactorOneItIsTheFineGridsStiffnessAndDamping) {
  HybridMesh::Options options = NotchedOptions(1);
  const HybridMesh mesh(options);
  EXPECT_EQ(mesh.num_hanging(), 0);
  const std::vector<Material> materials = TwoMaterials();
  const ElementSetStiffness regions(mesh, materials, AllElements(mesh));
  const HexGrid grid(kVoxels[0] + 1, kVoxels[1] + 1, kVoxels[2] + 1, kH);
  const ElasticModel fine(grid, MaterialField(grid, materials, CellMaterials()), DofConstraints{});

  Eigen::VectorXd u_grid = Eigen::VectorXd::Zero(grid.num_dofs());
  Eigen::VectorXd u_mesh(mesh.num_dofs());
  for (int r = 0; r < mesh.num_independent(); ++r) {
    const auto& p = mesh.LatticeOf(r);
    for (int c = 0; c < 3; ++c) {
      const double value = std::sin(1.7 * r + 0.9 * c) * 1e-3;  // any field will do
      u_mesh[mesh.Dof(r, c)] = value;
      u_grid[grid.Dof(grid.Node(p[0], p[1], p[2]), c)] = value;
    }
  }
  Eigen::VectorXd ku_mesh(mesh.num_dofs()), ku_grid(grid.num_dofs());
  regions.Apply(u_mesh, ku_mesh);
  fine.stiffness().Apply(u_grid, ku_grid);
  const Eigen::VectorXd damping = mesh.DofDamping(materials);
  double largest = 0, worst = 0;
  int between = 0;
  for (int r = 0; r < mesh.num_independent(); ++r) {
    const auto& p = mesh.LatticeOf(r);
    for (int c = 0; c < 3; ++c) {
      const int g = grid.Dof(grid.Node(p[0], p[1], p[2]), c), m = mesh.Dof(r, c);
      largest = std::max(largest, std::abs(ku_grid[g]));
      worst = std::max(worst, std::abs(ku_mesh[m] - ku_grid[g]));
      EXPECT_NEAR(damping[m], fine.dof_damping()[g], 1e-12) << "node " << r;
      between += damping[m] > 2 && damping[m] < 6;
    }
  }
  EXPECT_LT(worst, 1e-12 * largest);
  EXPECT_GT(between, 0) << "no node on the material boundary";
}

TEST(HybridMeshOnAnObject, TheBoxStencilTakesOneMaterialOnlyAndThenAgreesWithTheElements) {
  const HybridMesh mesh(NotchedOptions(1));
  const std::vector<Material> materials = TwoMaterials();
  EXPECT_EQ(BoxStiffness::TryMake(mesh, materials, AllElements(mesh)), nullptr)
      << "two materials in one box: the element loop";
  std::vector<int> tissue;
  for (int e : AllElements(mesh))
    if (mesh.elements()[e].material == 0) tissue.push_back(e);
  const auto box = BoxStiffness::TryMake(mesh, materials, tissue);
  ASSERT_NE(box, nullptr);
  const ElementSetStiffness elements(mesh, materials, tissue);
  Eigen::VectorXd u(mesh.num_dofs());
  // Each writes only the DOFs its elements touch: the rest stay zero in both.
  Eigen::VectorXd by_box = Eigen::VectorXd::Zero(mesh.num_dofs()), by_elements = by_box;
  for (int i = 0; i < u.size(); ++i) u[i] = std::cos(0.37 * i) * 1e-3;
  box->Apply(u, by_box);
  elements.Apply(u, by_elements);
  EXPECT_LT((by_box - by_elements).cwiseAbs().maxCoeff(), 1e-12 * by_elements.cwiseAbs().maxCoeff());
}

TEST(HybridMeshOnAnObject, EveryHeldNodeIsHeldExactly) {
  // The whole back face, and its part x ≤ 5 h: there a held node at x = 5 h would hang between a
  // held coarse vertex (x = 4 h) and a free one (6 h) unless its cell is refined (k = 2; at k = 3
  // the back face lies in cells the block fills only in part, refined anyway).
  std::vector<std::array<int, 3>> half;
  for (const auto& s : BackFace())
    if (s[0] <= 5) half.push_back(s);
  // And one node inside a coarse cell with no refinement around it (support_layers = 0): its
  // cell's vertices are free, so the cell is refined.
  const std::vector<std::array<int, 3>> inside{{5, 5, 7}};
  for (const auto& supports : {BackFace(), half, inside}) {
    for (int k : {2, 3}) {
      HybridMesh::Options options = NotchedOptions(k);
      options.supports = supports;
      options.support_layers = 0;
      const HybridMesh mesh(options);
      std::vector<char> held(static_cast<size_t>(mesh.num_independent()), 0);
      for (const auto& s : supports) {
        const int r = mesh.IndependentAt(s[0], s[1], s[2]);
        if (r >= 0) held[r] = 1;
      }
      for (const auto& s : supports) {
        std::array<GatherTerm, 8> terms;
        const int count = mesh.FieldAt(s, &terms);
        ASSERT_GT(count, 0);
        for (int i = 0; i < count; ++i) {
          EXPECT_TRUE(held[terms[i].independent])
              << supports.size() << " held, k = " << k << ": the held node " << s[0] << ", "
              << s[1] << " leans on a free node";
        }
      }
    }
  }
}

// The scene of the same object: the back face held by a plane, the contact the front-most node
// of the middle column, pressed 3 mm.
Scene NotchedScene(int primary_size, double secondary_rate_hz) {
  Scene scene = testing::VoxelScene(kVoxels[0], kVoxels[1], kVoxels[2], kH, NotchedBlockLabel);
  testing::HoldPlaneZ(&scene, kH * kVoxels[2]);
  const std::vector<Material> materials = TwoMaterials();
  scene.materials = {{1, materials[0]}, {2, materials[1]}};
  scene.input.amplitude_m = 0.003;
  scene.solver.dt_s = 0.0005;
  scene.adaptivity.primary_size = primary_size;
  scene.adaptivity.secondary_rate_hz = secondary_rate_hz;
  scene.adaptivity.outer_rate_hz = secondary_rate_hz;
  return scene;
}

TEST(AsyncRegionsOnAnObject, APressOverTheInclusionFollowsTheReference) {
  const SceneModel full(NotchedScene(0, 2000));
  const TrialResult reference = RunReferenceTrial(full);
  ASSERT_EQ(reference.outcome, TrialOutcome::kCompleted);
  AsyncRegions regions(NotchedScene(2, 2000));  // the secondary in step with the primary
  const RegionPartition& partition = regions.partition();
  EXPECT_EQ(partition.contact_node(), full.model().grid().NodeIndices(full.contact_node()));
  EXPECT_EQ(partition.contact_normal(), full.contact_normal());
  // The primary is fine, holds every voxel of the block inside the box of 2 nodes around the
  // contact, and no empty one (the box reaches past the front face).
  for (const HybridElement& e : partition.mesh().elements()) {
    if (e.region == kPrimaryRegion) {
      EXPECT_EQ(e.size_factor, 1);
    }
  }
  const std::vector<RegionIndex> region = partition.mesh().RegionPerLatticeCell();
  const LatticeIndex& c = partition.contact_node();
  for (int x = std::max(0, c[0] - 2); x < c[0] + 2; ++x)
    for (int y = std::max(0, c[1] - 2); y < c[1] + 2; ++y)
      for (int z = std::max(0, c[2] - 2); z < c[2] + 2; ++z) {
        const size_t cell = (static_cast<size_t>(x) * kVoxels[1] + y) * kVoxels[2] + z;
        EXPECT_EQ(region[cell], NotchedBlockLabel(x, y, z) > 0 ? kPrimaryRegion : -1)
            << "voxel " << x << ", " << y << ", " << z;
      }
  const TrialResult run = regions.RunTrial();
  ASSERT_EQ(run.outcome, TrialOutcome::kCompleted);
  const ForceError error = CompareForces(run.samples, reference.samples);
  std::printf("peak %.5f N against the reference's %.5f N; largest magnitude error %.2f %%, "
              "direction %.2f deg\n",
              run.peak_force_n, reference.peak_force_n, error.max_magnitude_percent,
              error.max_direction_deg);
  EXPECT_GT(reference.peak_force_n, 0.01);
  EXPECT_LT(error.max_magnitude_percent, 3.0) << "peak " << run.peak_force_n << " N against "
                                              << reference.peak_force_n << " N";
  EXPECT_LT(error.max_direction_deg, 5.0);
}

TEST(AsyncRegionsOnAnObject, ItsSurfaceIsThePointsBetweenTheBlockAndTheNotchOrTheOutside) {
  const AsyncRegions regions(NotchedScene(2, 2000));
  std::vector<std::int32_t> expected;
  const std::array<int, 3> n{kVoxels[0] + 1, kVoxels[1] + 1, kVoxels[2] + 1};
  for (int ix = 0; ix < n[0]; ++ix)
    for (int iy = 0; iy < n[1]; ++iy)
      for (int iz = 0; iz < n[2]; ++iz) {
        int filled = 0;
        for (int x : {ix - 1, ix})
          for (int y : {iy - 1, iy})
            for (int z : {iz - 1, iz})
              filled += x >= 0 && y >= 0 && z >= 0 && x < kVoxels[0] && y < kVoxels[1] &&
                        z < kVoxels[2] && NotchedBlockLabel(x, y, z) > 0;
        if (filled > 0 && filled < 8) expected.push_back((ix * n[1] + iy) * n[2] + iz);
      }
  EXPECT_EQ(regions.surface_ids(), expected);
}

TEST(AsyncRegionsOnAnObject, ItsStateCarriesToAnotherConfigurationOfTheSameObject) {
  AsyncRegions small(NotchedScene(2, 2000)), large(NotchedScene(3, 2000));
  InputSettings hold = small.partition().scene().input;
  hold.periods = 0.25;  // into the press
  ASSERT_EQ(small.RunTrial(hold).outcome, TrialOutcome::kCompleted);
  const ObjectState state = small.CaptureState();
  EXPECT_EQ(state.lattice_nodes, (std::array<int, 3>{12, 10, 11}));
  large.RestoreState(state);
  const ObjectState carried = large.CaptureState();
  // The contact and every node both meshes have carry their displacement unchanged.
  const auto& c = small.partition().contact_node();
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(carried.displacement_m[state.Index(c[0], c[1], c[2]) + i],
              state.displacement_m[state.Index(c[0], c[1], c[2]) + i]);
  }
  double moved = 0;
  for (int r = 0; r < small.partition().mesh().num_independent(); ++r) {
    const auto& p = small.partition().mesh().LatticeOf(r);
    if (large.partition().mesh().IndependentAt(p[0], p[1], p[2]) < 0) continue;
    const size_t i = state.Index(p[0], p[1], p[2]);
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(carried.displacement_m[i + k], state.displacement_m[i + k], 1e-15);
      moved = std::max(moved, std::abs(state.displacement_m[i + k]));
    }
  }
  EXPECT_GT(moved, 1e-4);
  // Where the large configuration has no node: in the notch, zero; inside a coarse cell (all its
  // 8 corners nodes of that mesh), the trilinear field of the corners' carried values.
  const HybridMesh& mesh = large.partition().mesh();
  int interpolated = 0;
  for (int ix = 0; ix <= kVoxels[0]; ++ix)
    for (int iy = 0; iy <= kVoxels[1]; ++iy)
      for (int iz = 0; iz <= kVoxels[2]; ++iz) {
        const size_t i = carried.Index(ix, iy, iz);
        if (ix >= 9 && iy >= 7) {  // touched by notch voxels only
          for (int k = 0; k < 3; ++k) EXPECT_EQ(carried.displacement_m[i + k], 0.0);
          continue;
        }
        if (mesh.IndependentAt(ix, iy, iz) >= 0) continue;
        const std::array<int, 3> low{ix / 2 * 2, iy / 2 * 2, iz / 2 * 2};
        if (low[0] + 2 > kVoxels[0] || low[1] + 2 > kVoxels[1] || low[2] + 2 > kVoxels[2]) {
          continue;  // a cell past the lattice's end: refined, not a coarse cell
        }
        bool corners = true;
        for (int corner = 0; corner < 8; ++corner)
          corners = corners && mesh.IndependentAt(low[0] + 2 * (corner & 1),
                                                  low[1] + 2 * ((corner >> 1) & 1),
                                                  low[2] + 2 * ((corner >> 2) & 1)) >= 0;
        if (!corners) continue;
        for (int k = 0; k < 3; ++k) {
          double value = 0;
          for (int corner = 0; corner < 8; ++corner) {
            const int b[3] = {corner & 1, (corner >> 1) & 1, (corner >> 2) & 1};
            double w = 1;
            const int p[3] = {ix, iy, iz};
            for (int a = 0; a < 3; ++a) w *= b[a] ? (p[a] - low[a]) / 2.0 : 1 - (p[a] - low[a]) / 2.0;
            value += w * carried.displacement_m[carried.Index(low[0] + 2 * b[0], low[1] + 2 * b[1],
                                                              low[2] + 2 * b[2]) + k];
          }
          EXPECT_NEAR(carried.displacement_m[i + k], value, 1e-15);
        }
        ++interpolated;
      }
  EXPECT_GT(interpolated, 0);
  ObjectState cube;
  cube.lattice_nodes = {13, 13, 13};
  cube.displacement_m.assign(3 * cube.num_points(), 0.0);
  cube.velocity_m_per_s = cube.displacement_m;
  EXPECT_THROW(large.RestoreState(cube), Error);
}

}  // namespace
}  // namespace hapticsim
