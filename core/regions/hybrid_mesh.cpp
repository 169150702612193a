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

// Which coarse cells are refined, and to which region each belongs.
struct CellPlan {
  int k = 1;   // fine intervals per coarse cell
  int nc = 0;  // coarse cells per axis
  std::vector<char> refined;
  std::vector<RegionIndex> region;
  int Index(int cx, int cy, int cz) const { return cx + nc * (cy + nc * cz); }
};

// Secondary shells: by Chebyshev distance (in coarse cells) to the nearest primary cell.
void AssignShells(const HybridMesh::Options& options, CellPlan* plan) {
  const int nc = plan->nc;
  std::vector<std::array<int, 3>> primary_cells;
  for (int cz = 0; cz < nc; ++cz)
    for (int cy = 0; cy < nc; ++cy)
      for (int cx = 0; cx < nc; ++cx)
        if (plan->region[plan->Index(cx, cy, cz)] == kPrimaryRegion)
          primary_cells.push_back({cx, cy, cz});
  for (int cz = 0; cz < nc; ++cz)
    for (int cy = 0; cy < nc; ++cy)
      for (int cx = 0; cx < nc; ++cx) {
        const int id = plan->Index(cx, cy, cz);
        if (plan->region[id] == kPrimaryRegion) continue;
        int distance = nc;
        for (const auto& c : primary_cells) {
          distance = std::min(
              distance, std::max({std::abs(cx - c[0]), std::abs(cy - c[1]), std::abs(cz - c[2])}));
        }
        const int shell = std::min(options.secondary_regions - 1,
                                   (distance - 1) / std::max(1, options.shell_cells));
        plan->region[id] = kSecondaryRegion + shell;
      }
}

CellPlan PlanCells(const HybridMesh::Options& options) {
  CellPlan plan;
  plan.k = options.coarse_factor;
  plan.nc = (options.nodes_per_axis - 1) / plan.k;
  const int k = plan.k, nc = plan.nc;
  plan.refined.assign(static_cast<size_t>(nc) * nc * nc, 0);
  plan.region.assign(plan.refined.size(), kSecondaryRegion);
  const int reach = options.support_layers * k;
  for (int cz = 0; cz < nc; ++cz) {
    for (int cy = 0; cy < nc; ++cy) {
      for (int cx = 0; cx < nc; ++cx) {
        const std::array<int, 3> c{cx, cy, cz};
        bool primary = true;
        for (int a = 0; a < 3; ++a) {
          primary = primary && CellOverlaps(c[a], k, options.primary_lo[a], options.primary_hi[a]);
        }
        bool near_support = false;
        for (const auto& s : options.supports) {
          bool near = reach > 0;
          for (int a = 0; a < 3; ++a)
            near = near && CellOverlaps(c[a], k, s[a] - reach, s[a] + reach);
          near_support = near_support || near;
        }
        const int id = plan.Index(cx, cy, cz);
        plan.refined[id] = (primary || near_support) && k > 1;
        plan.region[id] = primary ? kPrimaryRegion : kSecondaryRegion;
      }
    }
  }
  if (options.secondary_regions > 1) AssignShells(options, &plan);
  return plan;
}

// The masters of a hanging node at lattice point p — a node off the coarse lattice inside the
// closure of an unrefined cell takes that cell's trilinear interpolation of its 8 corners (which
// are never hanging) — as (mesh node, weight); empty when p is not hanging.
std::vector<std::pair<int, double>> HangingMasters(const std::array<int, 3>& p,
                                                   const CellPlan& plan,
                                                   const std::vector<int>& node_at_lattice,
                                                   int n) {
  const int k = plan.k, nc = plan.nc;
  std::vector<std::pair<int, double>> masters;
  if (p[0] % k == 0 && p[1] % k == 0 && p[2] % k == 0) return masters;  // coarse vertex
  // Candidate cells whose closure holds p: per axis floor(p/k), and the one below on a plane.
  std::array<std::array<int, 2>, 3> candidates{};
  std::array<int, 3> counts{};
  for (int a = 0; a < 3; ++a) {
    const int j = std::min(p[a] / k, nc - 1);
    candidates[a][counts[a]++] = j;
    if (p[a] % k == 0 && p[a] / k - 1 >= 0 && p[a] / k - 1 != j)
      candidates[a][counts[a]++] = p[a] / k - 1;
  }
  for (int ia = 0; ia < counts[0]; ++ia)
    for (int ib = 0; ib < counts[1]; ++ib)
      for (int ic = 0; ic < counts[2]; ++ic) {
        const std::array<int, 3> c{candidates[0][ia], candidates[1][ib], candidates[2][ic]};
        if (plan.refined[plan.Index(c[0], c[1], c[2])]) continue;
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
          if (w > 1e-14) {
            masters.push_back({node_at_lattice[corner[0] + n * (corner[1] + n * corner[2])], w});
          }
        }
        return masters;  // the first unrefined cell that holds it
      }
  return masters;
}

}  // namespace

HybridMesh::HybridMesh(const Options& options) : options_(options) {
  const int n = options.nodes_per_axis, k = options.coarse_factor;
  HAPTICSIM_THROW_UNLESS(n >= 2 && k >= 1 && (n - 1) % k == 0,
                         "the coarse factor " + std::to_string(k) + " must divide the " +
                             std::to_string(n - 1) + " node intervals");
  const CellPlan plan = PlanCells(options);
  const std::vector<std::array<int, 3>> node_lattice = BuildElements(plan.refined, plan.region);
  const int num_nodes = static_cast<int>(node_lattice.size());
  std::vector<std::vector<std::pair<int, double>>> masters(static_cast<size_t>(num_nodes));
  for (int node = 0; node < num_nodes; ++node) {
    masters[node] = HangingMasters(node_lattice[node], plan, node_at_lattice_, n);
    if (!masters[node].empty()) ++num_hanging_;
  }
  BuildGather(masters, node_lattice);
  BuildRegionMasks();
}

// A refined cell contributes its k³ fine elements, an unrefined one a single coarse element;
// nodes are created at the lattice points the elements use. Returns each node's lattice point.
std::vector<std::array<int, 3>> HybridMesh::BuildElements(const std::vector<char>& refined,
                                                          const std::vector<RegionIndex>& region) {
  const int n = options_.nodes_per_axis, k = options_.coarse_factor, nc = (n - 1) / k;
  node_at_lattice_.assign(static_cast<size_t>(n) * n * n, -1);
  std::vector<std::array<int, 3>> node_lattice;
  auto node_at = [&](int ix, int iy, int iz) {
    int& id = node_at_lattice_[ix + n * (iy + n * iz)];
    if (id < 0) {
      id = static_cast<int>(node_lattice.size());
      node_lattice.push_back({ix, iy, iz});
    }
    return id;
  };
  auto add_element = [&](int x0, int y0, int z0, int size, RegionIndex element_region) {
    HybridElement e;
    e.size_factor = size;
    e.region = element_region;
    for (int local = 0; local < 8; ++local) {
      e.nodes[local] = node_at(x0 + size * (local & 1), y0 + size * ((local >> 1) & 1),
                               z0 + size * ((local >> 2) & 1));
    }
    elements_.push_back(e);
  };
  for (int cz = 0; cz < nc; ++cz) {
    for (int cy = 0; cy < nc; ++cy) {
      for (int cx = 0; cx < nc; ++cx) {
        const int id = cx + nc * (cy + nc * cz);
        if (refined[id]) {
          for (int fz = 0; fz < k; ++fz)
            for (int fy = 0; fy < k; ++fy)
              for (int fx = 0; fx < k; ++fx)
                add_element(cx * k + fx, cy * k + fy, cz * k + fz, 1, region[id]);
        } else {
          add_element(cx * k, cy * k, cz * k, k, region[id]);
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
  const int n = options_.nodes_per_axis;
  const int node = node_at_lattice_[ix + n * (iy + n * iz)];
  return node < 0 ? -1 : independent_of_node_[node];
}

int HybridMesh::FieldAt(const std::array<int, 3>& p, std::array<GatherTerm, 8>* terms) const {
  if (const int node = IndependentAt(p[0], p[1], p[2]); node >= 0) {
    (*terms)[0] = {node, 1.0};
    return 1;
  }
  const int k = options_.coarse_factor;
  const int last_cell = (options_.nodes_per_axis - 1) / k - 1;
  std::array<int, 3> cell;
  std::array<double, 3> t;
  for (int d = 0; d < 3; ++d) {
    cell[d] = std::min(p[d] / k, last_cell);
    t[d] = static_cast<double>(p[d] - cell[d] * k) / k;
  }
  int count = 0;
  for (int corner = 0; corner < 8; ++corner) {
    double weight = 1;
    std::array<int, 3> vertex;
    for (int d = 0; d < 3; ++d) {
      const int up = (corner >> d) & 1;
      vertex[d] = (cell[d] + up) * k;
      weight *= up ? t[d] : 1 - t[d];
    }
    if (weight == 0) continue;
    const int node = IndependentAt(vertex[0], vertex[1], vertex[2]);
    HAPTICSIM_THROW_UNLESS(node >= 0, "internal: a coarse vertex is not a mesh node");
    (*terms)[count++] = {node, weight};
  }
  return count;
}

std::vector<RegionIndex> HybridMesh::RegionPerLatticeCell() const {
  const int n = options_.nodes_per_axis;
  // Each element's corner 0 (local offsets 0, 0, 0) is its lowest lattice point.
  std::vector<std::array<int, 3>> lattice_of_node(gather_start_.size() - 1, {-1, -1, -1});
  for (int iz = 0; iz < n; ++iz) {
    for (int iy = 0; iy < n; ++iy) {
      for (int ix = 0; ix < n; ++ix) {
        const int node = node_at_lattice_[ix + n * (iy + n * iz)];
        if (node >= 0) lattice_of_node[node] = {ix, iy, iz};
      }
    }
  }
  std::vector<RegionIndex> region(static_cast<size_t>(n - 1) * (n - 1) * (n - 1), -1);
  for (const HybridElement& element : elements_) {
    const std::array<int, 3> origin = lattice_of_node[element.nodes[0]];
    HAPTICSIM_THROW_UNLESS(origin[0] >= 0, "internal: an element's corner is not on the lattice");
    const int s = element.size_factor;
    for (int dx = 0; dx < s; ++dx) {
      for (int dy = 0; dy < s; ++dy) {
        for (int dz = 0; dz < s; ++dz) {
          const size_t cell =
              (static_cast<size_t>(origin[0] + dx) * (n - 1) + origin[1] + dy) * (n - 1) +
              origin[2] + dz;
          region[cell] = element.region;
        }
      }
    }
  }
  return region;
}

Eigen::VectorXd HybridMesh::DofMass(double density_kg_m3) const {
  const int nr = num_independent();
  Eigen::VectorXd node_mass = Eigen::VectorXd::Zero(nr);
  const double h = options_.spacing_m;
  for (const HybridElement& e : elements_) {
    const double edge = e.size_factor * h;
    const double share = density_kg_m3 * edge * edge * edge / 8.0;
    for (int node : e.nodes) {
      const auto [begin, end] = Gather(node);
      for (auto* g = begin; g != end; ++g) node_mass[g->independent] += g->weight * share;
    }
  }
  Eigen::VectorXd mass(3 * nr);
  for (int c = 0; c < 3; ++c) mass.segment(c * nr, nr) = node_mass;
  return mass;
}

}  // namespace hapticsim
