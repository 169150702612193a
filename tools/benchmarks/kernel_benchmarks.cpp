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
  options.lattice_nodes = {nodes, nodes, nodes};
  options.spacing_m = 0.25 / (nodes - 1);
  options.coarse_factor = 1;
  const HybridMesh mesh(options);
  std::vector<int> all(mesh.elements().size());
  for (size_t i = 0; i < all.size(); ++i) all[i] = static_cast<int>(i);
  const ElementSetStiffness k(mesh, {Material{}}, all);
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
  const ElementSetStiffness elements(mesh, {scene.material}, ids);
  const auto box = BoxStiffness::TryMake(mesh, {scene.material}, ids);
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

// The fields of BM_ElementwiseApply, on a grid filled to `percent` of its depth (the lower layers
// in z):
enum class AnyShapeField {
  kAlternating = 0,  // two materials alternating element by element (along x too): the worst case
                     // for node stencils, every run one node long
  kOneMaterial = 1,  // one material: a masked grid
  kInclusion = 2,    // soft, with a sphere 8× stiffer in the middle of the slab (a palpation
                     // phantom): two materials in contiguous regions
  kRandom = 3,       // two materials drawn at random per element: where the kernel choice matters
};

MaterialField AnyShape(const HexGrid& grid, int percent, AnyShapeField layout) {
  const int ex_count = grid.nx() - 1, ey_count = grid.ny() - 1;
  const int layers = (grid.nz() - 1) * percent / 100;
  std::vector<std::int16_t> elements(static_cast<size_t>(grid.num_elements()), -1);
  for (int e = 0; e < ex_count * ey_count * layers; ++e) {
    const int ex = e % ex_count, ey = (e / ex_count) % ey_count, ez = e / (ex_count * ey_count);
    // Element centre in units of the grid's edge; the sphere's radius is a fifth of the edge.
    const double x = (ex + 0.5) / ex_count - 0.5, y = (ey + 0.5) / ey_count - 0.5,
                 z = (ez + 0.5 - 0.5 * layers) / ex_count;
    const bool in_sphere = x * x + y * y + z * z < 0.2 * 0.2;
    switch (layout) {
      case AnyShapeField::kAlternating: elements[static_cast<size_t>(e)] = e % 2; break;
      case AnyShapeField::kOneMaterial: elements[static_cast<size_t>(e)] = 0; break;
      case AnyShapeField::kInclusion: elements[static_cast<size_t>(e)] = in_sphere; break;
      case AnyShapeField::kRandom:  // a multiplicative hash's bit
        elements[static_cast<size_t>(e)] = static_cast<std::int16_t>((e * 2654435761u >> 7) % 2);
    }
  }
  Material stiff;
  stiff.youngs_modulus_pa *= 8;
  return MaterialField(grid, {Material{}, stiff}, elements);
}

// Any shape, any materials: ElementwiseStiffness on the same grids as the stencil, a field of
// AnyShape (nodes, percent, field as arguments) with the kernel it chooses (kernel 0) or one
// forced (1 node stencils, 2 elements). "active_nodes" counts the nodes an occupied element
// touches: compare time per active node with the stencil's per node. "node_stencils" says which
// kernel ran.
void BM_ElementwiseApply(benchmark::State& state) {
  const HexGrid grid = Grid(static_cast<int>(state.range(0)));
  const MaterialField field = AnyShape(grid, static_cast<int>(state.range(1)),
                                       static_cast<AnyShapeField>(state.range(2)));
  const ElementwiseStiffness k(grid, field,
                               static_cast<ElementwiseStiffness::Kernel>(state.range(3)));
  const Eigen::VectorXd u = Field(grid.num_dofs());
  Eigen::VectorXd ku(grid.num_dofs());
  for (auto _ : state) {
    k.Apply(u, ku);
    benchmark::DoNotOptimize(ku.data());
  }
  const std::vector<bool> active = field.ActiveNodes(grid);
  state.counters["active_nodes"] =
      static_cast<double>(std::count(active.begin(), active.end(), true));
  state.counters["node_stencils"] = k.kernel() == ElementwiseStiffness::Kernel::kNodeStencils;
  state.counters["stencils"] = k.num_stencils();
  state.counters["windows"] = k.num_lane_stencils();
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
    ->ArgNames({"nodes", "percent", "field", "kernel"})
    ->ArgsProduct({{13, 25}, {100}, {0}, {0}})
    ->ArgsProduct({{13, 25}, {50}, {0, 1, 2, 3}, {0, 1, 2}})
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
