#include "core/regions/hybrid_mesh.hpp"

#include <algorithm>
#include <cstdlib>
#include <string>

#include "core/error.hpp"

namespace hapticsim {
namespace {

// Open-interval overlap of the coarse cell [j·k, (j+1)·k] with the closed index range [lo, hi]
// widened by nothing: the cell contains fine elements inside the range.
bool CellOverlaps(int j, int k, int lo, int hi) { return j * k < hi && (j + 1) * k > lo; }

enum class Cell : char { kEmpty, kCoarse, kRefined };

// What each coarse cell becomes, to which region it belongs, and of which material it is whole.
struct CellPlan {
  int k = 1;                // fine intervals per coarse cell
  std::array<int, 3> nc{};  // coarse cells per axis
  std::vector<Cell> state;
  std::vector<RegionIndex> region;
  std::vector<std::int16_t> material;  // a coarse cell's one material
  int Index(int cx, int cy, int cz) const { return cx + nc[0] * (cy + nc[1] * cz); }
  int Index(const std::array<int, 3>& c) const { return Index(c[0], c[1], c[2]); }
};

// The material of a fine lattice cell, or −1 outside the object or past the lattice's end.
std::int16_t FineCellMaterial(const HybridMesh::Options& o, int fx, int fy, int fz) {
  const auto& n = o.lattice_nodes;
  if (fx >= n[0] - 1 || fy >= n[1] - 1 || fz >= n[2] - 1) return -1;
  if (o.cell_material.empty()) return 0;
  return o.cell_material[static_cast<size_t>(fx) +
                         static_cast<size_t>(n[0] - 1) * (fy + static_cast<size_t>(n[1] - 1) * fz)];
}

// Whether the object fills coarse cell c wholly with one material, which; −2 when it is empty.
int WholeMaterial(const HybridMesh::Options& o, int k, const std::array<int, 3>& c) {
  int material = -1, occupied = 0;
  bool uniform = true;
  for (int fz = c[2] * k; fz < (c[2] + 1) * k; ++fz)
    for (int fy = c[1] * k; fy < (c[1] + 1) * k; ++fy)
      for (int fx = c[0] * k; fx < (c[0] + 1) * k; ++fx) {
        const int m = FineCellMaterial(o, fx, fy, fz);
        if (m < 0) continue;
        if (occupied++ == 0) material = m;
        uniform = uniform && m == material;
      }
  if (occupied == 0) return -2;
  return uniform && occupied == k * k * k ? material : -1;
}

// The candidate coarse cells whose closure holds lattice point p, the cell p's index falls in
// first: per axis floor(p/k) (the last cell at the far end), and the one below on a cell plane.
template <typename Each>
void ForEachCellHolding(const std::array<int, 3>& p, int k, const std::array<int, 3>& nc,
                        Each&& each) {
  std::array<std::array<int, 2>, 3> candidates{};
  std::array<int, 3> counts{};
  for (int a = 0; a < 3; ++a) {
    const int j = std::min(p[a] / k, nc[a] - 1);
    candidates[a][counts[a]++] = j;
    if (p[a] % k == 0 && p[a] / k - 1 >= 0 && p[a] / k - 1 != j)
      candidates[a][counts[a]++] = p[a] / k - 1;
  }
  for (int ia = 0; ia < counts[0]; ++ia)
    for (int ib = 0; ib < counts[1]; ++ib)
      for (int ic = 0; ic < counts[2]; ++ic)
        if (each(std::array<int, 3>{candidates[0][ia], candidates[1][ib], candidates[2][ic]}))
          return;
}

// The trilinear weights of coarse cell c's 8 vertices at lattice point p, `each(vertex, w)` for
// those of non-zero weight, in Hex8Element's local order.
template <typename Each>
void ForEachVertexWeight(const std::array<int, 3>& p, const std::array<int, 3>& c, int k,
                         Each&& each) {
  std::array<double, 3> t{};
  for (int a = 0; a < 3; ++a) t[a] = double(p[a] - c[a] * k) / k;
  for (int local = 0; local < 8; ++local) {
    double w = 1.0;
    std::array<int, 3> corner{};
    for (int a = 0; a < 3; ++a) {
      const int bit = (local >> a) & 1;
      w *= bit ? t[a] : 1.0 - t[a];
      corner[a] = (c[a] + bit) * k;
    }
    if (w > 1e-14) each(corner, w);
  }
}

// Held nodes as a sorted list of padded-lattice indices (Supports::Held).
struct Supports {
  std::array<int, 3> padded{};
  std::vector<long> held;
  long Key(const std::array<int, 3>& p) const {
    return p[0] + static_cast<long>(padded[0]) * (p[1] + static_cast<long>(padded[1]) * p[2]);
  }
  bool Held(const std::array<int, 3>& p) const {
    for (int a = 0; a < 3; ++a)
      if (p[a] < 0 || p[a] >= padded[a]) return false;
    return std::binary_search(held.begin(), held.end(), Key(p));
  }
  // A point support or a node of a held line (the corner of an L of lines too): both are
  // singular, the displacement near them unbounded in the continuum, so a coarse cell there is
  // far too stiff. A node of a held surface is not: it is a corner of a held parallelogram of
  // lattice neighbours, p, p + a, p + b, p + a + b with a and b not parallel (a unit square of
  // an axis-aligned face; a rhombus of a diagonal plane's nodes).
  bool PointOrLine(const std::array<int, 3>& p) const {
    std::array<std::array<int, 3>, 26> held{};
    int count = 0;
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx)
          if ((dx || dy || dz) && Held({p[0] + dx, p[1] + dy, p[2] + dz})) {
            held[count++] = {dx, dy, dz};
          }
    for (int i = 0; i < count; ++i) {
      for (int j = i + 1; j < count; ++j) {
        const auto& a = held[i];
        const auto& b = held[j];
        const bool parallel =
            a[1] * b[2] == a[2] * b[1] && a[2] * b[0] == a[0] * b[2] && a[0] * b[1] == a[1] * b[0];
        if (!parallel && Held({p[0] + a[0] + b[0], p[1] + a[1] + b[1], p[2] + a[2] + b[2]})) {
          return false;
        }
      }
    }
    return true;
  }
};

// Secondary shells: by Chebyshev distance (in coarse cells) to the nearest primary cell.
void AssignShells(const HybridMesh::Options& options, CellPlan* plan) {
  const auto& nc = plan->nc;
  std::vector<std::array<int, 3>> primary_cells;
  for (int cz = 0; cz < nc[2]; ++cz)
    for (int cy = 0; cy < nc[1]; ++cy)
      for (int cx = 0; cx < nc[0]; ++cx) {
        const int id = plan->Index(cx, cy, cz);
        if (plan->state[id] != Cell::kEmpty && plan->region[id] == kPrimaryRegion)
          primary_cells.push_back({cx, cy, cz});
      }
  const int far = std::max({nc[0], nc[1], nc[2]});
  for (int cz = 0; cz < nc[2]; ++cz)
    for (int cy = 0; cy < nc[1]; ++cy)
      for (int cx = 0; cx < nc[0]; ++cx) {
        const int id = plan->Index(cx, cy, cz);
        if (plan->state[id] == Cell::kEmpty || plan->region[id] == kPrimaryRegion) continue;
        int distance = far;
        for (const auto& c : primary_cells) {
          distance = std::min(
              distance, std::max({std::abs(cx - c[0]), std::abs(cy - c[1]), std::abs(cz - c[2])}));
        }
        const int shell = std::min(options.secondary_regions - 1,
                                   (distance - 1) / std::max(1, options.shell_cells));
        plan->region[id] = kSecondaryRegion + shell;
      }
}

// A held node that would hang from a coarse cell with a free vertex of non-zero weight would not
// be held: that cell is refined. Refining only removes coarse cells, so one pass is enough.
void RefineAtHangingSupports(const Supports& supports, const std::vector<std::array<int, 3>>& held,
                             CellPlan* plan) {
  const int k = plan->k;
  for (const auto& p : held) {
    if (p[0] % k == 0 && p[1] % k == 0 && p[2] % k == 0) continue;  // a coarse vertex
    ForEachCellHolding(p, k, plan->nc, [&](const std::array<int, 3>& c) {
      Cell& state = plan->state[plan->Index(c)];
      if (state != Cell::kCoarse) return false;
      bool all_held = true;
      ForEachVertexWeight(p, c, k, [&](const std::array<int, 3>& v, double) {
        all_held = all_held && supports.Held(v);
      });
      if (!all_held) state = Cell::kRefined;
      return false;  // every cell that holds it
    });
  }
}

CellPlan PlanCells(const HybridMesh::Options& options, const std::array<int, 3>& padded) {
  CellPlan plan;
  plan.k = options.coarse_factor;
  const int k = plan.k;
  for (int a = 0; a < 3; ++a) plan.nc[a] = (padded[a] - 1) / k;
  const size_t cells = static_cast<size_t>(plan.nc[0]) * plan.nc[1] * plan.nc[2];
  plan.state.assign(cells, Cell::kEmpty);
  plan.region.assign(cells, kSecondaryRegion);
  plan.material.assign(cells, 0);
  Supports supports{padded, {}};
  for (const auto& s : options.supports) supports.held.push_back(supports.Key(s));
  std::sort(supports.held.begin(), supports.held.end());
  std::vector<std::array<int, 3>> singular_supports;
  for (const auto& s : options.supports)
    if (supports.PointOrLine(s)) singular_supports.push_back(s);
  const int reach = options.support_layers * k;
  for (int cz = 0; cz < plan.nc[2]; ++cz) {
    for (int cy = 0; cy < plan.nc[1]; ++cy) {
      for (int cx = 0; cx < plan.nc[0]; ++cx) {
        const std::array<int, 3> c{cx, cy, cz};
        const int whole = WholeMaterial(options, k, c);
        if (whole == -2) continue;  // empty
        bool primary = true;
        for (int a = 0; a < 3; ++a) {
          primary = primary && CellOverlaps(c[a], k, options.primary_lo[a], options.primary_hi[a]);
        }
        bool near_support = false;
        for (const auto& s : singular_supports) {
          bool near = reach > 0;
          for (int a = 0; a < 3; ++a)
            near = near && CellOverlaps(c[a], k, s[a] - reach, s[a] + reach);
          near_support = near_support || near;
        }
        const int id = plan.Index(c);
        const bool refined = whole < 0 || ((primary || near_support) && k > 1);
        plan.state[id] = refined ? Cell::kRefined : Cell::kCoarse;
        plan.material[id] = static_cast<std::int16_t>(std::max(whole, 0));
        plan.region[id] = primary ? kPrimaryRegion : kSecondaryRegion;
      }
    }
  }
  RefineAtHangingSupports(supports, options.supports, &plan);
  if (options.secondary_regions > 1) AssignShells(options, &plan);
  return plan;
}

// The masters of a hanging node at lattice point p — a node off the coarse lattice inside the
// closure of an unrefined cell takes that cell's trilinear interpolation of its 8 corners (which
// are never hanging) — as (mesh node, weight); empty when p is not hanging.
std::vector<std::pair<int, double>> HangingMasters(const std::array<int, 3>& p,
                                                   const CellPlan& plan,
                                                   const std::vector<int>& node_at_lattice,
                                                   const std::array<int, 3>& padded) {
  const int k = plan.k;
  std::vector<std::pair<int, double>> masters;
  if (p[0] % k == 0 && p[1] % k == 0 && p[2] % k == 0) return masters;  // coarse vertex
  ForEachCellHolding(p, k, plan.nc, [&](const std::array<int, 3>& c) {
    if (plan.state[plan.Index(c)] != Cell::kCoarse) return false;
    ForEachVertexWeight(p, c, k, [&](const std::array<int, 3>& v, double w) {
      masters.push_back({node_at_lattice[v[0] + padded[0] * (v[1] + padded[1] * v[2])], w});
    });
    return true;  // the first unrefined cell that holds it
  });
  return masters;
}

}  // namespace

HybridMesh::HybridMesh(const Options& options) : options_(options) {
  const auto& n = options.lattice_nodes;
  const int k = options.coarse_factor;
  HAPTICSIM_THROW_UNLESS(n[0] >= 2 && n[1] >= 2 && n[2] >= 2 && k >= 1,
                         "internal: a hybrid mesh needs 2 or more lattice points per axis and a "
                         "coarse factor of 1 or more");
  const size_t fine_cells = static_cast<size_t>(n[0] - 1) * (n[1] - 1) * (n[2] - 1);
  HAPTICSIM_THROW_UNLESS(
      options.cell_material.empty() || options.cell_material.size() == fine_cells,
      "internal: the cell materials are not the lattice's cells");
  for (int a = 0; a < 3; ++a) {
    coarse_cells_[a] = (n[a] - 1 + k - 1) / k;
    padded_[a] = coarse_cells_[a] * k + 1;
  }
  for (const auto& s : options.supports)
    for (int a = 0; a < 3; ++a)
      HAPTICSIM_THROW_UNLESS(s[a] >= 0 && s[a] < n[a], "internal: a support is off the lattice");
  const CellPlan plan = PlanCells(options, padded_);
  coarse_.resize(plan.state.size());
  for (size_t c = 0; c < coarse_.size(); ++c) coarse_[c] = plan.state[c] == Cell::kCoarse;
  const std::vector<std::array<int, 3>> node_lattice = BuildElements(plan);
  HAPTICSIM_THROW_UNLESS(!elements_.empty(), "internal: a hybrid mesh of an empty object");
  const int num_nodes = static_cast<int>(node_lattice.size());
  std::vector<std::vector<std::pair<int, double>>> masters(static_cast<size_t>(num_nodes));
  for (int node = 0; node < num_nodes; ++node) {
    masters[node] = HangingMasters(node_lattice[node], plan, node_at_lattice_, padded_);
    if (!masters[node].empty()) ++num_hanging_;
  }
  BuildGather(masters, node_lattice);
  BuildRegionMasks();
}

// A refined cell contributes its occupied fine elements, an unrefined one a single coarse
// element; nodes are created at the lattice points the elements use. Returns each node's lattice
// point.
template <typename Plan>
std::vector<std::array<int, 3>> HybridMesh::BuildElements(const Plan& plan) {
  const int k = options_.coarse_factor;
  node_at_lattice_.assign(static_cast<size_t>(padded_[0]) * padded_[1] * padded_[2], -1);
  std::vector<std::array<int, 3>> node_lattice;
  auto node_at = [&](int ix, int iy, int iz) {
    int& id = node_at_lattice_[LatticePoint(ix, iy, iz)];
    if (id < 0) {
      id = static_cast<int>(node_lattice.size());
      node_lattice.push_back({ix, iy, iz});
    }
    return id;
  };
  auto add_element = [&](int x0, int y0, int z0, int size, RegionIndex region, int material) {
    HybridElement e;
    e.size_factor = size;
    e.region = region;
    e.material = static_cast<std::int16_t>(material);
    for (int local = 0; local < 8; ++local) {
      e.nodes[local] = node_at(x0 + size * (local & 1), y0 + size * ((local >> 1) & 1),
                               z0 + size * ((local >> 2) & 1));
    }
    elements_.push_back(e);
  };
  for (int cz = 0; cz < plan.nc[2]; ++cz) {
    for (int cy = 0; cy < plan.nc[1]; ++cy) {
      for (int cx = 0; cx < plan.nc[0]; ++cx) {
        const int id = plan.Index(cx, cy, cz);
        if (plan.state[id] == Cell::kCoarse) {
          add_element(cx * k, cy * k, cz * k, k, plan.region[id], plan.material[id]);
          continue;
        }
        if (plan.state[id] == Cell::kEmpty) continue;
        for (int fz = cz * k; fz < (cz + 1) * k; ++fz)
          for (int fy = cy * k; fy < (cy + 1) * k; ++fy)
            for (int fx = cx * k; fx < (cx + 1) * k; ++fx) {
              const int material = FineCellMaterial(options_, fx, fy, fz);
              if (material >= 0) add_element(fx, fy, fz, 1, plan.region[id], material);
            }
      }
    }
  }
  return node_lattice;
}
// The independent nodes (those not hanging), and every node's gather: itself, or its masters.
void HybridMesh::BuildGather(const std::vector<std::vector<std::pair<int, double>>>& masters,
                             const std::vector<std::array<int, 3>>& node_lattice) {
  const int num_nodes = static_cast<int>(node_lattice.size());
  independent_of_node_.assign(static_cast<size_t>(num_nodes), -1);
  for (int node = 0; node < num_nodes; ++node) {
    if (masters[node].empty()) {
      independent_of_node_[node] = static_cast<int>(independent_lattice_.size());
      independent_lattice_.push_back(node_lattice[node]);
    }
  }
  gather_start_.assign(static_cast<size_t>(num_nodes) + 1, 0);
  for (int node = 0; node < num_nodes; ++node) {
    if (masters[node].empty()) {
      gather_terms_.push_back({independent_of_node_[node], 1.0});
    } else {
      for (const auto& [master, w] : masters[node]) {
        HAPTICSIM_THROW_UNLESS(independent_of_node_[master] >= 0,
                               "internal: a hanging node's master is itself hanging");
        gather_terms_.push_back({independent_of_node_[master], w});
      }
    }
    gather_start_[node + 1] = static_cast<int>(gather_terms_.size());
  }
}

// Which regions' elements touch each independent node (through the gathers).
void HybridMesh::BuildRegionMasks() {
  region_mask_.assign(independent_lattice_.size(), 0u);
  for (const HybridElement& e : elements_) {
    num_regions_ = std::max(num_regions_, e.region + 1);
    for (int node : e.nodes) {
      const auto [begin, end] = Gather(node);
      for (auto* g = begin; g != end; ++g) region_mask_[g->independent] |= 1u << e.region;
    }
  }
}

int HybridMesh::IndependentAt(int ix, int iy, int iz) const {
  const int node = node_at_lattice_[LatticePoint(ix, iy, iz)];
  return node < 0 ? -1 : independent_of_node_[node];
}

int HybridMesh::FieldAt(const std::array<int, 3>& p, std::array<GatherTerm, 8>* terms) const {
  if (const int node = IndependentAt(p[0], p[1], p[2]); node >= 0) {
    (*terms)[0] = {node, 1.0};
    return 1;
  }
  const int k = options_.coarse_factor;
  int count = 0;
  ForEachCellHolding(p, k, coarse_cells_, [&](const std::array<int, 3>& c) {
    if (!coarse_[c[0] + coarse_cells_[0] * (c[1] + coarse_cells_[1] * c[2])]) return false;
    ForEachVertexWeight(p, c, k, [&](const std::array<int, 3>& v, double w) {
      const int node = IndependentAt(v[0], v[1], v[2]);
      HAPTICSIM_THROW_UNLESS(node >= 0, "internal: a coarse vertex is not a mesh node");
      (*terms)[count++] = {node, w};
    });
    return true;
  });
  return count;
}

std::vector<RegionIndex> HybridMesh::RegionPerLatticeCell() const {
  const auto& n = options_.lattice_nodes;
  // Each element's corner 0 (local offsets 0, 0, 0) is its lowest lattice point.
  std::vector<std::array<int, 3>> lattice_of_node(gather_start_.size() - 1, {-1, -1, -1});
  for (int iz = 0; iz < padded_[2]; ++iz) {
    for (int iy = 0; iy < padded_[1]; ++iy) {
      for (int ix = 0; ix < padded_[0]; ++ix) {
        const int node = node_at_lattice_[LatticePoint(ix, iy, iz)];
        if (node >= 0) lattice_of_node[node] = {ix, iy, iz};
      }
    }
  }
  std::vector<RegionIndex> region(static_cast<size_t>(n[0] - 1) * (n[1] - 1) * (n[2] - 1), -1);
  for (const HybridElement& element : elements_) {
    const std::array<int, 3> origin = lattice_of_node[element.nodes[0]];
    HAPTICSIM_THROW_UNLESS(origin[0] >= 0, "internal: an element's corner is not on the lattice");
    const int s = element.size_factor;
    for (int dx = 0; dx < s; ++dx) {
      for (int dy = 0; dy < s; ++dy) {
        for (int dz = 0; dz < s; ++dz) {
          const size_t cell =
              (static_cast<size_t>(origin[0] + dx) * (n[1] - 1) + origin[1] + dy) * (n[2] - 1) +
              origin[2] + dz;
          region[cell] = element.region;
        }
      }
    }
  }
  return region;
}

Eigen::VectorXd HybridMesh::NodeMass(const std::vector<Material>& materials,
                                     bool times_damping) const {
  Eigen::VectorXd node_mass = Eigen::VectorXd::Zero(num_independent());
  const double h = options_.spacing_m;
  for (const HybridElement& e : elements_) {
    const Material& material = materials.at(e.material);
    const double edge = e.size_factor * h;
    double share = material.density_kg_m3 * edge * edge * edge / 8.0;
    if (times_damping) share *= material.damping_per_s;
    for (int node : e.nodes) {
      const auto [begin, end] = Gather(node);
      for (auto* g = begin; g != end; ++g) node_mass[g->independent] += g->weight * share;
    }
  }
  return node_mass;
}

Eigen::VectorXd HybridMesh::DofMass(const std::vector<Material>& materials) const {
  const int nr = num_independent();
  const Eigen::VectorXd node_mass = NodeMass(materials, false);
  Eigen::VectorXd mass(3 * nr);
  for (int c = 0; c < 3; ++c) mass.segment(c * nr, nr) = node_mass;
  return mass;
}

Eigen::VectorXd HybridMesh::DofDamping(const std::vector<Material>& materials) const {
  const double first = materials.at(elements_.front().material).damping_per_s;
  const bool one_rate = std::all_of(
      elements_.begin(), elements_.end(),
      [&](const HybridElement& e) { return materials.at(e.material).damping_per_s == first; });
  if (one_rate) return Eigen::VectorXd::Constant(num_dofs(), first);
  // Σ_e d_e·M_e lumped, divided by Σ_e M_e.
  const int nr = num_independent();
  const Eigen::VectorXd node_rate =
      NodeMass(materials, true).cwiseQuotient(NodeMass(materials, false));
  Eigen::VectorXd rate(3 * nr);
  for (int c = 0; c < 3; ++c) rate.segment(c * nr, nr) = node_rate;
  return rate;
}

int HybridMesh::OccupiedCellsAround(const std::array<int, 3>& p) const {
  int occupied = 0;
  for (int corner = 0; corner < 8; ++corner) {
    std::array<int, 3> cell{};
    for (int a = 0; a < 3; ++a) cell[a] = p[a] - 1 + ((corner >> a) & 1);
    if (cell[0] < 0 || cell[1] < 0 || cell[2] < 0) continue;
    occupied += FineCellMaterial(options_, cell[0], cell[1], cell[2]) >= 0;
  }
  return occupied;
}

int HybridMesh::uniform_material() const {
  const int first = elements_.front().material;
  for (const HybridElement& e : elements_)
    if (e.material != first) return -1;
  return first;
}

}  // namespace hapticsim
