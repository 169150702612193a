// K·u matrix-free (27-point stencil) against the assembled Eigen CSR product, and one full
// central-difference step, on 13³, 25³ and 49³ grids. Run:
//
//   build/tools/benchmarks/hapticsim_kernel_benchmarks --benchmark_min_time=0.5
//
// The counters give the ratio that matters on a shared machine: both kernels run in the same
// process, one after the other, on the same inputs. "GFLOP/s" counts 2 flops per stored
// coupling of the stencil (the assembled product does the same arithmetic on ~2× the entries,
// since it stores the zero couplings the stencil drops).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <vector>

#include "core/fem/assembled_stiffness.hpp"
#include "core/regions/box_stiffness.hpp"
#include "core/fem/central_difference_integrator.hpp"
#include "core/fem/elementwise_stiffness.hpp"
#include "core/fem/material_field.hpp"
#include "core/scene/scene_model.hpp"
#include "core/regions/element_set_stiffness.hpp"
#include "core/regions/hybrid_mesh.hpp"
#include "core/regions/region_partition.hpp"
#include "core/fem/stencil_stiffness.hpp"

namespace hapticsim {
namespace {

HexGrid Grid(int nodes) { return HexGrid(nodes, nodes, nodes, 0.25 / (nodes - 1)); }

Eigen::VectorXd Field(int size) { return Eigen::VectorXd::LinSpaced(size, -1e-3, 1e-3); }

void BM_StencilApply(benchmark::State& state) {
  const HexGrid grid = Grid(static_cast<int>(state.range(0)));
  const StencilStiffness k(grid, Material{});
  const Eigen::VectorXd u = Field(grid.num_dofs());
  Eigen::VectorXd ku(grid.num_dofs());
  for (auto _ : state) {
    k.Apply(u, ku);
    benchmark::DoNotOptimize(ku.data());
  }
  state.counters["GFLOP/s"] =
      benchmark::Counter(k.FlopsPerApply() * 1e-9, benchmark::Counter::kIsIterationInvariantRate);
  state.counters["nodes"] = grid.num_nodes();
}

void BM_AssembledApply(benchmark::State& state) {
  const HexGrid grid = Grid(static_cast<int>(state.range(0)));
  const AssembledStiffness k(grid, Material{});
  const Eigen::VectorXd u = Field(grid.num_dofs());
  Eigen::VectorXd ku(grid.num_dofs());
  for (auto _ : state) {
    k.Apply(u, ku);
    benchmark::DoNotOptimize(ku.data());
  }
  state.counters["GFLOP/s"] = benchmark::Counter(2.0 * k.matrix().nonZeros() * 1e-9,
                                                 benchmark::Counter::kIsIterationInvariantRate);
  state.counters["nodes"] = grid.num_nodes();
}

// The regions' generic element loop (24×24 per element, hanging-node gathers) on the same full
// grid (k = 1, so no hanging nodes): what the asynchronous regions pay per node against the
// stencil.
void BM_ElementLoopApply(benchmark::State& state) {
  const int nodes = static_cast<int>(state.range(0));
  HybridMesh::Options options;
  options.nodes_per_axis = nodes;
  options.spacing_m = 0.25 / (nodes - 1);
  options.coarse_factor = 1;
  const HybridMesh mesh(options);
  std::vector<int> all(mesh.elements().size());
  for (size_t i = 0; i < all.size(); ++i) all[i] = static_cast<int>(i);
  const ElementSetStiffness k(mesh, Material{}, all);
  const Eigen::VectorXd u = Field(mesh.num_dofs());
  Eigen::VectorXd ku(mesh.num_dofs());
  for (auto _ : state) {
    k.Apply(u, ku);
    benchmark::DoNotOptimize(ku.data());
  }
  state.counters["nodes"] = mesh.num_independent();
}

// One region of the paper's 13³ cube (primary size, spacing factor, region as arguments): K·u by
// the element loop (use_box 0) or by BoxStiffness, node stencils on the region's bounding box
// with its nodes gathered and scattered (use_box 1), on the same mesh and field. Region 0 is the
// primary (a box), region 1 at spacing 1 a box with the primary's box as its hole.
void BM_RegionApply(benchmark::State& state) {
  Scene scene;
  scene.adaptivity.primary_size = static_cast<int>(state.range(0));
  scene.adaptivity.secondary_lod = static_cast<int>(state.range(1));
  const auto region = static_cast<RegionIndex>(state.range(2));
  const RegionPartition partition(scene);
  const HybridMesh& mesh = partition.mesh();
  std::vector<int> ids;
  for (int e = 0; e < static_cast<int>(mesh.elements().size()); ++e) {
    if (mesh.elements()[static_cast<size_t>(e)].region == region) ids.push_back(e);
  }
  const ElementSetStiffness elements(mesh, scene.material, ids);
  const auto box = BoxStiffness::TryMake(mesh, scene.material, ids);
  if (!box) {
    state.SkipWithError("the region's elements are not all fine");
    return;
  }
  const StiffnessOperator& k =
      state.range(3) ? static_cast<const StiffnessOperator&>(*box) : elements;
  const Eigen::VectorXd u = Field(mesh.num_dofs());
  Eigen::VectorXd ku(mesh.num_dofs());
  for (auto _ : state) {
    k.Apply(u, ku);
    benchmark::DoNotOptimize(ku.data());
  }
  state.counters["elements"] = static_cast<double>(ids.size());
  state.counters["direct_nodes"] = box->direct_nodes();
}

// Any shape, any materials: the element-by-element operator (ElementwiseStiffness) on the same
// grids, filled whole (range 1 = 100) or to a half (50: the lower half in z, the object a slab of
// half the cube; two materials, so nothing is uniform). "active_nodes" counts the nodes an
// occupied element touches: compare time per active node with the stencil's per node.
void BM_ElementwiseApply(benchmark::State& state) {
  const HexGrid grid = Grid(static_cast<int>(state.range(0)));
  const int percent = static_cast<int>(state.range(1));
  Material stiff;
  stiff.youngs_modulus_pa *= 8;
  std::vector<std::int16_t> elements(static_cast<size_t>(grid.num_elements()));
  const int layers = (grid.nz() - 1) * percent / 100;
  for (int e = 0; e < grid.num_elements(); ++e) {
    const int ez = e / ((grid.nx() - 1) * (grid.ny() - 1));
    elements[static_cast<size_t>(e)] = ez < layers ? static_cast<std::int16_t>(e % 2) : -1;
  }
  const MaterialField field(grid, {Material{}, stiff}, elements);
  const ElementwiseStiffness k(grid, field);
  const Eigen::VectorXd u = Field(grid.num_dofs());
  Eigen::VectorXd ku(grid.num_dofs());
  for (auto _ : state) {
    k.Apply(u, ku);
    benchmark::DoNotOptimize(ku.data());
  }
  const std::vector<bool> active = field.ActiveNodes(grid);
  state.counters["active_nodes"] =
      static_cast<double>(std::count(active.begin(), active.end(), true));
}

void BM_TimeStep(benchmark::State& state) {
  Scene scene;
  scene.mesh.nodes = static_cast<int>(state.range(0));
  scene.solver.dt_s = 1e-4;  // below the limit at every size benchmarked
  const SceneModel cube(scene);
  CentralDifferenceIntegrator integrator(cube.model(), scene.solver.dt_s);
  const std::array<double, 3> next{0, 0, 1e-3};
  for (auto _ : state) {
    benchmark::DoNotOptimize(integrator.Step(next));
  }
  state.counters["nodes"] = cube.model().grid().num_nodes();
}

BENCHMARK(BM_StencilApply)->Arg(13)->Arg(25)->Arg(49)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_AssembledApply)->Arg(13)->Arg(25)->Arg(49)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_ElementwiseApply)
    ->Args({13, 100})
    ->Args({13, 50})
    ->Args({25, 100})
    ->Args({25, 50})
    ->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_ElementLoopApply)->Arg(13)->Arg(25)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_RegionApply)
    ->ArgNames({"primary_size", "spacing", "region", "use_box"})
    ->ArgsProduct({{4}, {3}, {0}, {0, 1}})
    ->ArgsProduct({{3}, {2}, {0}, {0, 1}})
    ->ArgsProduct({{1, 2, 3, 4}, {1}, {1}, {0, 1}})
    ->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_TimeStep)->Arg(13)->Arg(25)->Arg(49)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace hapticsim

BENCHMARK_MAIN();
