#include "core/regions/region_partition.hpp"

#include <algorithm>
#include <string>

#include "core/regions/box_stiffness.hpp"
#include "core/error.hpp"
#include "core/scene/scene_model.hpp"

namespace hapticsim {

namespace {
// The shortest rows (nodes along x and y) for which a box region runs on the stencil.
constexpr int kMinBoxRowNodes = 9;

// The hybrid mesh the scene's adaptivity asks for on the scene's object: the primary box around
// the contact node (clipped to the object by the mesh: only occupied cells), the supports, the
// shells.
HybridMesh::Options MeshOptionsOf(const Scene& scene, const SceneObject& object) {
  const HexGrid& grid = object.grid;
  const int r = scene.adaptivity.primary_size;
  const std::array<int, 3> contact = grid.NodeIndices(object.contact_node);
  const std::array<int, 3> last{grid.nx() - 1, grid.ny() - 1, grid.nz() - 1};
  HybridMesh::Options options;
  options.lattice_nodes = {grid.nx(), grid.ny(), grid.nz()};
  options.spacing_m = grid.spacing();
  options.coarse_factor = scene.adaptivity.secondary_lod;
  const MaterialField& field = object.field;
  options.cell_material.resize(static_cast<size_t>(field.num_elements()));
  for (int e = 0; e < field.num_elements(); ++e) options.cell_material[e] = field.material_of(e);
  for (int a = 0; a < 3; ++a) {
    options.primary_lo[a] = std::max(0, contact[a] - r);
    options.primary_hi[a] = std::min(last[a], contact[a] + r);
  }
  for (int node : object.fixed_nodes) options.supports.push_back(grid.NodeIndices(node));
  options.support_layers = scene.adaptivity.support_layers;
  options.secondary_regions = scene.adaptivity.secondary_regions;
  options.shell_cells = scene.adaptivity.shell_cells;
  return options;
}

// Each region's elements. @throws Error when a secondary region has none.
std::vector<std::vector<int>> ElementsByRegion(const HybridMesh& mesh, const Scene& scene) {
  const int regions = 1 + scene.adaptivity.secondary_regions;
  std::vector<std::vector<int>> elements(static_cast<size_t>(regions));
  for (int e = 0; e < static_cast<int>(mesh.elements().size()); ++e) {
    elements[mesh.elements()[e].region].push_back(e);
  }
  for (int region = 1; region < regions; ++region) {
    HAPTICSIM_THROW_UNLESS(
        !elements[region].empty(),
        "adaptivity.primary_size = " + std::to_string(scene.adaptivity.primary_size) +
            (regions == 2
                 ? std::string(" leaves no secondary region")
                 : " leaves secondary region " + std::to_string(region) +
                       " of adaptivity.secondary_regions = " + std::to_string(regions - 1) +
                       " empty: use fewer or thinner shells"));
  }
  return elements;
}

}  // namespace

RegionPartition::RegionPartition(const Scene& scene) : scene_(scene) {
  HAPTICSIM_THROW_UNLESS(scene.adaptivity.enabled(),
                         "asynchronous regions need adaptivity.primary_size >= 1");
  const SceneObject object = DescribeSceneObject(scene);
  materials_ = object.field.materials();
  contact_lattice_ = object.grid.NodeIndices(object.contact_node);
  contact_normal_ = object.contact_normal;
  const HybridMesh::Options options = MeshOptionsOf(scene, object);
  mesh_ = std::make_unique<HybridMesh>(options);
  dof_mass_ = mesh_->DofMass(materials_);
  dof_damping_ = mesh_->DofDamping(materials_);
  const std::vector<std::vector<int>> elements = ElementsByRegion(*mesh_, scene);
  for (const std::vector<int>& region_elements : elements) {
    // Fine elements (the primary box; at spacing factor 1 the secondary shells too, boxes with a
    // hole) run on node stencils where their bounding box's rows are long enough for the vector
    // path: measured per K·u against the element loop, a 13×13×7 primary box 2.0× faster,
    // 9×9×5 1.3×, 7×7×4 the same, 3×3×2 2.3× slower (face nodes, the scalar path, are nearly all
    // of a small box); a 13³ secondary with a hole 1.5–3.0× faster (docs/benchmarks.md).
    if (auto box =
            BoxStiffness::TryMake(*mesh_, materials_, region_elements, kMinBoxRowNodes)) {
      stiffness_.push_back(std::move(box));
    } else {
      stiffness_.push_back(
          std::make_unique<ElementSetStiffness>(*mesh_, materials_, region_elements));
    }
  }
  AssignDofs(options.supports, static_cast<int>(elements.size()));
  FindBands(elements);
}

void RegionPartition::AssignDofs(const std::vector<std::array<int, 3>>& supports, int regions) {
  const LatticeIndex& contact = contact_lattice_;
  const int contact_node = mesh_->IndependentAt(contact[0], contact[1], contact[2]);
  HAPTICSIM_THROW_UNLESS(contact_node >= 0, "internal: the contact node is not independent");
  for (int c = 0; c < 3; ++c) contact_dofs_[c] = mesh_->Dof(contact_node, c);
  std::vector<std::array<int, 3>> not_nodes;  // held lattice points with no node of their own
  for (const auto& s : supports) {
    const int node = mesh_->IndependentAt(s[0], s[1], s[2]);
    // A held node that hangs (or lies inside a coarse cell) takes the field of held nodes only
    // (HybridMesh refines where it would not), so it is held through them: checked below.
    if (node < 0) {
      not_nodes.push_back(s);
      continue;
    }
    for (int c = 0; c < 3; ++c) fixed_dofs_.push_back(mesh_->Dof(node, c));
  }
  std::sort(fixed_dofs_.begin(), fixed_dofs_.end());
  std::array<GatherTerm, 8> terms;
  for (const auto& s : not_nodes) {
    const int count = mesh_->FieldAt(s, &terms);
    for (int i = 0; i < count; ++i) {
      HAPTICSIM_THROW_UNLESS(std::binary_search(fixed_dofs_.begin(), fixed_dofs_.end(),
                                                mesh_->Dof(terms[i].independent, 0)),
                             "internal: a held node leans on a free node");
    }
  }

  const auto& mask = mesh_->region_mask();
  const int nr = mesh_->num_independent();
  HAPTICSIM_THROW_UNLESS(mask[contact_node] == 1u,
                         "internal: the contact must lie inside the primary region");
  dofs_.resize(static_cast<size_t>(regions));
  for (int c = 0; c < 3; ++c) {
    for (int node = 0; node < nr; ++node) {
      const unsigned m = mask[node];
      const int dof = c * nr + node;
      // Nested shells: a node belongs to one region or to two neighbours.
      const int outermost = 31 - __builtin_clz(m);
      const int innermost = __builtin_ctz(m);
      HAPTICSIM_THROW_UNLESS(outermost - innermost <= 1,
                             "internal: regions " + std::to_string(innermost) + " and " +
                                 std::to_string(outermost) + " touch without the shell between");
      if (std::binary_search(fixed_dofs_.begin(), fixed_dofs_.end(), dof)) {
        for (int region = innermost; region <= outermost; ++region)
          dofs_[region].fixed.push_back(dof);
        continue;
      }
      if (!proxy_contact() &&
          std::find(contact_dofs_.begin(), contact_dofs_.end(), dof) != contact_dofs_.end())
        continue;
      dofs_[outermost].owned.push_back(dof);
      if (outermost != innermost) {
        dofs_[outermost].inner_interface.push_back(dof);
        dofs_[innermost].outer_interface.push_back(dof);
      }
    }
  }
}

// The band of each region next to its outer interface.
void RegionPartition::FindBands(const std::vector<std::vector<int>>& elements) {
  const int regions = static_cast<int>(elements.size());
  const int nr = mesh_->num_independent();
  band_.resize(static_cast<size_t>(regions));
  for (int region = 0; region + 1 < regions; ++region) {
    std::vector<char> on_gamma(static_cast<size_t>(nr), 0);
    for (int dof : dofs_[region].outer_interface) on_gamma[dof % nr] = 1;
    for (int e : elements[region]) {
      bool touches = false;
      for (int node : mesh_->elements()[e].nodes) {
        const auto [begin, end] = mesh_->Gather(node);
        for (auto* g = begin; g != end; ++g) touches = touches || on_gamma[g->independent];
      }
      if (touches) band_[region].push_back(e);
    }
  }
}

ProxySurface RegionPartition::PrimaryProxySurface() const {
  const HybridMesh& mesh = *mesh_;
  ProxySurface surface;
  surface.lattice_nodes = mesh.options().lattice_nodes;
  surface.spacing_m = mesh.options().spacing_m;
  const std::array<int, 3>& n = surface.lattice_nodes;
  const auto cells = static_cast<std::size_t>((n[0] - 1) * (n[1] - 1) * (n[2] - 1));
  const std::vector<std::int16_t>& material = mesh.options().cell_material;
  surface.occupied.assign(cells, 1);
  for (std::size_t e = 0; e < material.size(); ++e) surface.occupied[e] = material[e] >= 0 ? 1 : 0;
  const auto nodes = static_cast<std::size_t>(surface.num_nodes());
  surface.dof.assign(nodes, -1);
  surface.loadable.assign(nodes, -1);
  surface.mass_kg.assign(nodes, 0.0);
  surface.component_stride = mesh.num_independent();
  for (int iz = 0; iz < n[2]; ++iz) {
    for (int iy = 0; iy < n[1]; ++iy) {
      for (int ix = 0; ix < n[0]; ++ix) {
        const int r = mesh.IndependentAt(ix, iy, iz);
        if (r < 0 || !(dof_mass_[mesh.Dof(r, 0)] > 0)) continue;
        const auto node = static_cast<std::size_t>(surface.Node({ix, iy, iz}));
        const int dof = mesh.Dof(r, 0);
        surface.dof[node] = dof;
        surface.mass_kg[node] = dof_mass_[dof];
        if (std::binary_search(fixed_dofs_.begin(), fixed_dofs_.end(), dof)) {
          surface.loadable[node] = 0;
        } else if (mesh.region_mask()[r] == 1u) {  // the primary's alone: not on Γ
          surface.loadable[node] = 1;
        }
      }
    }
  }
  return surface;
}

int RegionPartition::num_elements(RegionIndex region) const {
  return static_cast<int>(
      std::count_if(mesh_->elements().begin(), mesh_->elements().end(),
                    [&](const HybridElement& e) { return e.region == region; }));
}

int RegionPartition::num_nodes(RegionIndex region) const {
  return static_cast<int>(std::count_if(mesh_->region_mask().begin(), mesh_->region_mask().end(),
                                        [&](unsigned m) { return (m >> region) & 1u; }));
}

bool RegionPartition::PrimaryOneElementDeep() const {
  const std::vector<int>& gamma = dofs_[kPrimaryRegion].outer_interface;
  if (gamma.empty()) return false;  // the primary alone: no Γ
  std::vector<char> on_gamma(static_cast<size_t>(mesh_->num_independent()), 0);
  for (int dof : gamma) on_gamma[static_cast<size_t>(dof % mesh_->num_independent())] = 1;
  for (const HybridElement& element : mesh_->elements()) {
    if (element.region != kPrimaryRegion) continue;
    bool touches = false;
    for (int node : element.nodes) {
      const auto [begin, end] = mesh_->Gather(node);
      for (const GatherTerm* term = begin; term != end; ++term) {
        touches = touches || on_gamma[static_cast<size_t>(term->independent)];
      }
    }
    if (!touches) return false;
  }
  return true;
}

std::string RegionPartition::RegionName(RegionIndex region) const {
  if (region == kPrimaryRegion) return "primary";
  if (num_regions() == 2) return "secondary";
  return "secondary " + std::to_string(region);
}

}  // namespace hapticsim
