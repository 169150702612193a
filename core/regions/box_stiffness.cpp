#include "core/regions/box_stiffness.hpp"

#include <algorithm>
#include <climits>

#include "core/fem/cpu_dispatch.hpp"

namespace hapticsim {
namespace {

// Corner offset of Hex8Element's local node: bx + 2·by + 4·bz.
std::array<int, 3> Offset(int local) { return {local & 1, (local >> 1) & 1, (local >> 2) & 1}; }

}  // namespace

std::unique_ptr<BoxStiffness> BoxStiffness::TryMake(const HybridMesh& mesh,
                                                    const std::vector<Material>& materials,
                                                    const std::vector<int>& element_ids,
                                                    int min_row_nodes) {
  if (element_ids.empty()) return nullptr;
  // One material: one stencil per set of cells around a node (several would need one per
  // 8-tuple of materials, as StencilStiffness has on the fine grid).
  const int material = mesh.elements()[static_cast<size_t>(element_ids.front())].material;
  for (int id : element_ids) {
    if (mesh.elements()[static_cast<size_t>(id)].material != material) return nullptr;
  }
  // Each element's lowest corner on the fine lattice, from one of its independent nodes (every
  // fine element has one: a refined cell's centre, or a coarse vertex).
  std::vector<std::array<int, 3>> origins;
  origins.reserve(element_ids.size());
  std::array<int, 3> low{INT_MAX, INT_MAX, INT_MAX}, high{INT_MIN, INT_MIN, INT_MIN};
  for (int id : element_ids) {
    const HybridElement& e = mesh.elements()[static_cast<size_t>(id)];
    if (e.size_factor != 1) return nullptr;
    bool found = false;
    std::array<int, 3> origin{};
    for (int local = 0; local < 8 && !found; ++local) {
      const auto [begin, end] = mesh.Gather(e.nodes[local]);
      if (end - begin != 1 || begin->weight != 1.0) continue;
      const std::array<int, 3>& at = mesh.LatticeOf(begin->independent);
      if (mesh.IndependentAt(at[0], at[1], at[2]) != begin->independent) continue;
      for (int c = 0; c < 3; ++c) origin[c] = at[c] - Offset(local)[c];
      found = true;
    }
    if (!found) return nullptr;
    origins.push_back(origin);
    for (int c = 0; c < 3; ++c) {
      low[c] = std::min(low[c], origin[c]);
      high[c] = std::max(high[c], origin[c]);
    }
  }
  const std::array<int, 3> cells{high[0] - low[0] + 1, high[1] - low[1] + 1, high[2] - low[2] + 1};
  const std::array<int, 3> nodes{cells[0] + 1, cells[1] + 1, cells[2] + 1};
  if (nodes[0] < min_row_nodes || nodes[1] < min_row_nodes) return nullptr;
  std::vector<int> box_mesh_nodes(static_cast<size_t>(nodes[0]) * nodes[1] * nodes[2], -1);
  // Per grid node, which of its 8 cells are among the elements (MakeNodeStencil's bits).
  std::vector<unsigned> cell_masks(box_mesh_nodes.size(), 0);
  std::vector<char> seen(static_cast<size_t>(cells[0]) * cells[1] * cells[2], 0);
  for (size_t i = 0; i < element_ids.size(); ++i) {
    const std::array<int, 3> o{origins[i][0] - low[0], origins[i][1] - low[1],
                               origins[i][2] - low[2]};
    const size_t cell = static_cast<size_t>(o[0] + cells[0] * (o[1] + cells[1] * o[2]));
    if (seen[cell]) return nullptr;  // an element twice
    seen[cell] = 1;
    const HybridElement& e = mesh.elements()[static_cast<size_t>(element_ids[i])];
    for (int local = 0; local < 8; ++local) {
      const std::array<int, 3> d = Offset(local);
      const size_t node = static_cast<size_t>(
          (o[0] + d[0]) + nodes[0] * ((o[1] + d[1]) + nodes[1] * (o[2] + d[2])));
      if (box_mesh_nodes[node] >= 0 && box_mesh_nodes[node] != e.nodes[local]) return nullptr;
      box_mesh_nodes[node] = e.nodes[local];
      // Seen from that node, this cell lies on its low side along the axes where d is 1.
      cell_masks[node] |= 1u << (d[0] | (d[1] << 1) | (d[2] << 2));
    }
  }
  return std::unique_ptr<BoxStiffness>(
      new BoxStiffness(mesh, materials, material, element_ids, nodes, std::move(box_mesh_nodes),
                       cell_masks));
}

BoxStiffness::BoxStiffness(const HybridMesh& mesh, const std::vector<Material>& materials,
                           int material, std::vector<int> element_ids, const std::array<int, 3>& box_nodes,
                           std::vector<int> box_mesh_nodes, const std::vector<unsigned>& cell_masks)
    : StiffnessOperator(mesh.num_dofs()),
      mesh_(mesh),
      elements_(mesh, materials, std::move(element_ids)),
      box_nodes_(box_nodes) {
  // One stencil per distinct set of cells, and the rows cut into runs of one stencil each.
  const Hex8Element::Matrix24 ke = Hex8Element::Stiffness(mesh.options().spacing_m, materials.at(material));
  const std::ptrdiff_t nb = static_cast<std::ptrdiff_t>(box_mesh_nodes.size());
  std::array<int, 256> stencil_of;
  stencil_of.fill(-1);
  for (std::ptrdiff_t row = 0; row < nb; row += box_nodes[0]) {
    for (int ix = 0; ix < box_nodes[0]; ++ix) {
      const unsigned mask = cell_masks[static_cast<size_t>(row + ix)];
      if (mask == 0) continue;  // in the hole: no element of ours touches it
      if (stencil_of[mask] < 0) {
        stencil_of[mask] = static_cast<int>(stencils_.size());
        stencils_.push_back(MakeNodeStencil(
            ke, mask, nb, box_nodes[0], static_cast<std::ptrdiff_t>(box_nodes[0]) * box_nodes[1]));
      }
      if (!runs_.empty() && runs_.back().stencil == stencil_of[mask] &&
          runs_.back().first + runs_.back().length == row + ix && ix > 0) {
        ++runs_.back().length;
      } else {
        runs_.push_back({row + ix, 1, stencil_of[mask]});
      }
    }
  }

  gather_start_.push_back(0);
  for (int node : box_mesh_nodes) {
    if (node >= 0) {  // (not in the hole)
      const auto [begin, end] = mesh.Gather(node);
      gather_terms_.insert(gather_terms_.end(), begin, end);
    }
    gather_start_.push_back(static_cast<int>(gather_terms_.size()));
  }
  u_box_.setZero(3 * static_cast<Eigen::Index>(box_mesh_nodes.size()));
  ku_box_.setZero(u_box_.size());

  const int nr = mesh.num_independent();
  std::vector<int> references(static_cast<size_t>(nr), 0);
  for (const GatherTerm& g : gather_terms_) ++references[static_cast<size_t>(g.independent)];
  std::vector<char> written(static_cast<size_t>(mesh.num_dofs()), 0);
  for (int b = 0; b + 1 < static_cast<int>(gather_start_.size()); ++b) {
    if (gather_start_[b + 1] == gather_start_[b]) continue;  // in the hole
    const GatherTerm& first = gather_terms_[static_cast<size_t>(gather_start_[b])];
    if (gather_start_[b + 1] - gather_start_[b] == 1 && first.weight == 1.0 &&
        references[static_cast<size_t>(first.independent)] == 1) {
      direct_nodes_.push_back({b, first.independent});
      for (int c = 0; c < 3; ++c) written[static_cast<size_t>(c * nr + first.independent)] = 1;
    } else {
      weighted_nodes_.push_back(b);
    }
  }
  for (int dof : touched_dofs()) {
    if (!written[static_cast<size_t>(dof)]) zeroed_dofs_.push_back(dof);
  }
}

HAPTICSIM_KERNEL_CLONES
void BoxStiffness::ApplyOnBox(const double* u, double* ku) const {
  const int nr = mesh_.num_independent();
  const int nb = static_cast<int>(gather_start_.size()) - 1;
  for (const DirectNode& d : direct_nodes_) {
    u_box_[d.box] = u[d.independent];
    u_box_[nb + d.box] = u[nr + d.independent];
    u_box_[2 * nb + d.box] = u[2 * nr + d.independent];
  }
  for (int b : weighted_nodes_) {
    double x = 0, y = 0, z = 0;
    for (int t = gather_start_[b]; t < gather_start_[b + 1]; ++t) {
      const GatherTerm& g = gather_terms_[static_cast<size_t>(t)];
      x += g.weight * u[g.independent];
      y += g.weight * u[nr + g.independent];
      z += g.weight * u[2 * nr + g.independent];
    }
    u_box_[b] = x;
    u_box_[nb + b] = y;
    u_box_[2 * nb + b] = z;
  }
  for (const Run& run : runs_) {
    ApplyStencilRun(stencils_[static_cast<size_t>(run.stencil)], u_box_.data(), ku_box_.data(),
                    run.first, run.length, nb);
  }
  for (const DirectNode& d : direct_nodes_) {
    ku[d.independent] = ku_box_[d.box];
    ku[nr + d.independent] = ku_box_[nb + d.box];
    ku[2 * nr + d.independent] = ku_box_[2 * nb + d.box];
  }
  for (int dof : zeroed_dofs_) ku[dof] = 0.0;
  for (int b : weighted_nodes_) {
    for (int t = gather_start_[b]; t < gather_start_[b + 1]; ++t) {
      const GatherTerm& g = gather_terms_[static_cast<size_t>(t)];
      ku[g.independent] += g.weight * ku_box_[b];
      ku[nr + g.independent] += g.weight * ku_box_[nb + b];
      ku[2 * nr + g.independent] += g.weight * ku_box_[2 * nb + b];
    }
  }
}

void BoxStiffness::Apply(const Eigen::Ref<const Eigen::VectorXd>& u,
                         Eigen::Ref<Eigen::VectorXd> ku) const {
  ApplyOnBox(u.data(), ku.data());
}

}  // namespace hapticsim
