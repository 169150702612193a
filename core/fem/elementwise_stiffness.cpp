#include "core/fem/elementwise_stiffness.hpp"

#include <algorithm>
#include <cassert>
#include <cstdint>
#include <map>

#include "core/fem/cpu_dispatch.hpp"

namespace hapticsim {
namespace {

// The material of each of the 8 cells around a node (CellMatrices' order), kEmpty where no
// element is: what decides the node's row of K.
using CellMaterials = std::array<std::int16_t, 8>;

CellMaterials MaterialsAround(const HexGrid& grid, const MaterialField& field, int ix, int iy,
                              int iz) {
  CellMaterials cells;
  for (int cell = 0; cell < 8; ++cell) {
    const int ex = ix - (cell & 1), ey = iy - ((cell >> 1) & 1), ez = iz - ((cell >> 2) & 1);
    const bool inside = ex >= 0 && ex + 1 < grid.nx() && ey >= 0 && ey + 1 < grid.ny() &&
                        ez >= 0 && ez + 1 < grid.nz();
    cells[static_cast<size_t>(cell)] =
        inside ? field.material_of(field.Element(ex, ey, ez)) : MaterialField::kEmpty;
  }
  return cells;
}

bool NoCellPresent(const CellMaterials& cells) {
  return std::all_of(cells.begin(), cells.end(),
                     [](std::int16_t m) { return m == MaterialField::kEmpty; });
}

// Costs of the two kernels, in units of one node of a vectorised run (the full cube's stencil:
// ~14–16 ns a node on this machine's AVX2), measured with tools/benchmarks/kernel_benchmarks.cpp
// (BM_ElementwiseApply with the kernel forced; docs/benchmarks.md): a node of a run shorter than
// 4 outside a window (the scalar ApplyStencilAt), a merged window of 4 nodes, an element (one
// 24 × 24 vector product with its gathers and scatters). Nodes no element touches cost either
// kernel about the same (a store) and are left out.
constexpr double kScalarNodeCost = 4.4;
constexpr double kLaneWindowCost = 6.0;
constexpr double kElementCost = 3.0;
// Beyond this many distinct cell tuples (a field mixed at random) the node stencils would not
// stay in cache; their windows would seldom repeat either: the element kernel, without building
// them.
constexpr size_t kMostStencils = 2048;
constexpr int kShortestVectorRun = 4;  // ApplyStencilRun's narrowest vector, a window's width

// The end of the run of nodes of one class that starts at `ix` in a row.
int RunEnd(const int* class_of, int ix, int nx) {
  int end = ix + 1;
  while (end < nx && class_of[end] == class_of[ix]) ++end;
  return end;
}

}  // namespace

struct ElementwiseStiffness::NodeClasses {
  std::vector<CellMaterials> cells;  // per distinct class (= node stencil)
  std::vector<int> class_of;         // per node
};

ElementwiseStiffness::ElementwiseStiffness(const HexGrid& grid, const MaterialField& field,
                                           Kernel kernel)
    : StiffnessOperator(grid.num_dofs()), num_nodes_(grid.num_nodes()), kernel_(kernel) {
  for (const Material& material : field.materials()) {
    stiffness_.push_back(Hex8Element::Stiffness(grid.spacing(), material));
  }
  elements_.reserve(static_cast<size_t>(field.num_occupied()));
  field.ForEachOccupied(grid, [&](const std::array<int, 8>& nodes, int material) {
    elements_.push_back({nodes, material});
  });
  if (kernel_ == Kernel::kElements) return;
  const NodeClasses classes = ClassifyNodes(grid, field);
  if (kernel_ == Kernel::kAuto && classes.cells.size() > kMostStencils) {
    kernel_ = Kernel::kElements;
    return;
  }
  BuildStencils(grid, classes);
  LaneIndex lane_index;
  for (int iz = 0; iz < grid.nz(); ++iz) {
    for (int iy = 0; iy < grid.ny(); ++iy) {
      const int row = grid.Node(0, iy, iz);
      SegmentRow(row, grid.nx(), classes.class_of.data() + row, &lane_index);
    }
  }
  if (kernel_ == Kernel::kAuto) kernel_ = ChooseKernel(classes);
  if (kernel_ == Kernel::kElements) {
    stencils_ = {};
    lane_stencils_ = {};
    segments_ = {};
  }
}

auto ElementwiseStiffness::ClassifyNodes(const HexGrid& grid, const MaterialField& field) const
    -> NodeClasses {
  NodeClasses classes;
  classes.class_of.reserve(static_cast<size_t>(grid.num_nodes()));
  std::map<CellMaterials, int> class_index;
  for (int iz = 0; iz < grid.nz(); ++iz) {
    for (int iy = 0; iy < grid.ny(); ++iy) {
      for (int ix = 0; ix < grid.nx(); ++ix) {
        const CellMaterials cells = MaterialsAround(grid, field, ix, iy, iz);
        const auto [it, inserted] =
            class_index.emplace(cells, static_cast<int>(classes.cells.size()));
        if (inserted) classes.cells.push_back(cells);
        classes.class_of.push_back(it->second);
      }
    }
  }
  return classes;
}

void ElementwiseStiffness::BuildStencils(const HexGrid& grid, const NodeClasses& classes) {
  const std::ptrdiff_t sy = grid.nx();
  const std::ptrdiff_t sz = static_cast<std::ptrdiff_t>(grid.nx()) * grid.ny();
  stencils_.reserve(classes.cells.size());
  for (const CellMaterials& materials : classes.cells) {
    CellMatrices cells{};
    for (size_t cell = 0; cell < 8; ++cell) {
      const std::int16_t m = materials[cell];
      cells[cell] = m == MaterialField::kEmpty ? nullptr : &stiffness_[static_cast<size_t>(m)];
    }
    stencils_.push_back(MakeNodeStencil(cells, num_nodes_, sy, sz));
  }
}

// Runs of 4 nodes or more as they are; the stretches of shorter runs between them in windows of
// 4. A window may reach back or ahead over nodes another segment also writes: it writes the same
// rows of K, so whichever comes last is right.
void ElementwiseStiffness::SegmentRow(std::ptrdiff_t row, int nx, const int* class_of,
                                      LaneIndex* lane_index) {
  int ix = 0;
  while (ix < nx) {
    const int end = RunEnd(class_of, ix, nx);
    if (end - ix >= kShortestVectorRun || nx < kShortestVectorRun) {
      segments_.push_back({row + ix, end - ix, class_of[ix], false});
      ix = end;
      continue;
    }
    int stretch_end = end;
    while (stretch_end < nx) {
      const int next = RunEnd(class_of, stretch_end, nx);
      if (next - stretch_end >= kShortestVectorRun) break;
      stretch_end = next;
    }
    for (int from = ix; from < stretch_end; from += kShortestVectorRun) {
      AddWindow(row, nx, class_of, from, std::min(from + kShortestVectorRun, stretch_end),
                lane_index);
    }
    ix = stretch_end;
  }
}

// Nodes [from, to) of a row (at most 4) by the window of 4 that holds them, or one by one where
// the window's lanes would read outside u (at the two ends of the grid).
void ElementwiseStiffness::AddWindow(std::ptrdiff_t row, int nx, const int* class_of, int from,
                                     int to, LaneIndex* lane_index) {
  const int window = std::min(from, nx - kShortestVectorRun);
  std::array<int, 4> lanes;
  std::array<const NodeStencil*, 4> lane_nodes;
  for (size_t k = 0; k < 4; ++k) {
    lanes[k] = class_of[window + static_cast<int>(k)];
    lane_nodes[k] = &stencils_[static_cast<size_t>(lanes[k])];
  }
  auto [it, inserted] = lane_index->emplace(lanes, static_cast<int>(lane_stencils_.size()));
  if (inserted) lane_stencils_.push_back(MergeNodeStencils(lane_nodes));
  if (LaneReadsInside(lane_stencils_[static_cast<size_t>(it->second)], row + window, num_nodes_)) {
    segments_.push_back({row + window, kShortestVectorRun, it->second, true});
    return;
  }
  for (int ix = from; ix < to; ++ix) segments_.push_back({row + ix, 1, class_of[ix], false});
}

auto ElementwiseStiffness::ChooseKernel(const NodeClasses& classes) const -> Kernel {
  double node_cost = 0.0;
  for (const Segment& segment : segments_) {
    if (segment.lanes) {
      node_cost += kLaneWindowCost;
    } else if (!NoCellPresent(classes.cells[static_cast<size_t>(segment.stencil)])) {
      node_cost += segment.length * (segment.length >= kShortestVectorRun ? 1.0 : kScalarNodeCost);
    }
  }
  const double element_cost = kElementCost * static_cast<double>(elements_.size());
  return node_cost <= element_cost ? Kernel::kNodeStencils : Kernel::kElements;
}

HAPTICSIM_KERNEL_CLONES
void ElementwiseStiffness::ApplyElements(const double* u, double* ku) const {
  static_assert(!Hex8Element::Matrix24::IsRowMajor, "MultiplyElement24 reads columns");
  const int n = num_nodes_;
  std::fill(ku, ku + 3 * static_cast<std::ptrdiff_t>(n), 0.0);
  double ue[24], fe[24];
  for (const Element& e : elements_) {
    // Local DOFs are node-major (3·local node + component); the grid's are component-blocked.
    for (int local = 0; local < 8; ++local) {
      for (int c = 0; c < 3; ++c) ue[3 * local + c] = u[c * n + e.nodes[local]];
    }
    MultiplyElement24(stiffness_[static_cast<size_t>(e.material)].data(), ue, fe);
    for (int local = 0; local < 8; ++local) {
      for (int c = 0; c < 3; ++c) ku[c * n + e.nodes[local]] += fe[3 * local + c];
    }
  }
}

HAPTICSIM_KERNEL_CLONES
void ElementwiseStiffness::ApplySegments(const double* u, double* ku) const {
  // The segments cover every node, so every entry of ku is written (inactive nodes' with 0).
  const std::ptrdiff_t n = num_nodes_;
  for (const Segment& segment : segments_) {
    const size_t stencil = static_cast<size_t>(segment.stencil);
    if (segment.lanes) {
      ApplyLaneStencil(lane_stencils_[stencil], u, ku, segment.first, n);
    } else {
      ApplyStencilRun(stencils_[stencil], u, ku, segment.first, segment.length, n);
    }
  }
}

void ElementwiseStiffness::Apply(const Eigen::Ref<const Eigen::VectorXd>& u,
                                 Eigen::Ref<Eigen::VectorXd> ku) const {
  assert(u.size() == num_dofs() && ku.size() == num_dofs());
  if (kernel_ == Kernel::kNodeStencils) {
    ApplySegments(u.data(), ku.data());
  } else {
    ApplyElements(u.data(), ku.data());
  }
}

Eigen::VectorXd ElementwiseStiffness::Diagonal() const {
  Eigen::VectorXd diagonal = Eigen::VectorXd::Zero(num_dofs());
  for (const Element& e : elements_) {
    const Hex8Element::Matrix24& k = stiffness_[static_cast<size_t>(e.material)];
    for (int local = 0; local < 8; ++local) {
      for (int c = 0; c < 3; ++c) {
        diagonal[c * num_nodes_ + e.nodes[local]] += k(3 * local + c, 3 * local + c);
      }
    }
  }
  return diagonal;
}

}  // namespace hapticsim
