// The object's surface as the running regions see it, for drawing (AsyncRegions::surface_ids,
// RequestSurface, SurfaceServed, ReadSurface): each region publishes the owned DOFs the surface
// needs into a seqlocked array of its own when a reader has asked, after its step, so the steps
// stay real-time; the reader sums them into the surface's displacements.
#include <algorithm>
#include <array>

#include "core/regions/async_regions.hpp"
#include "core/regions/async_regions_region.hpp"
#include "core/error.hpp"

namespace hapticsim {

// The surface points in id order; each of their values as terms of the regions' own DOFs: a
// point with an independent node its owner's value, any other its coarse cell's field
// (HybridMesh::FieldAt). The contact's DOFs are the primary's (prescribed there); the supports'
// are zero, so they have no term.
void AsyncRegions::BuildSurface() {
  const HybridMesh& mesh = partition_.mesh();
  const auto [nx, ny, nz] = mesh.options().lattice_nodes;
  std::vector<RegionIndex> owner(static_cast<size_t>(mesh.num_dofs()), -1);
  for (int a = 0; a < num_regions(); ++a) {
    for (int dof : partition_.dofs(a).owned) owner[dof] = a;
  }
  for (int dof : partition_.contact_dofs()) owner[dof] = kPrimaryRegion;
  std::vector<int> slot(owner.size(), -1);  // each DOF's place in its owner's surface_dofs
  auto slot_of = [&](int dof) {
    if (slot[dof] < 0) {
      std::vector<int>& dofs = regions_[owner[dof]]->surface_dofs;
      slot[dof] = static_cast<int>(dofs.size());
      dofs.push_back(dof);
    }
    return slot[dof];
  };
  surface_ = SurfaceMap{};
  surface_.term_start.push_back(0);
  std::array<GatherTerm, 8> field;
  for (int ix = 0; ix < nx; ++ix) {
    for (int iy = 0; iy < ny; ++iy) {
      for (int iz = 0; iz < nz; ++iz) {
        const int occupied = mesh.OccupiedCellsAround({ix, iy, iz});
        if (occupied == 0 || occupied == 8) continue;  // outside, or inside the object
        surface_.ids.push_back((ix * ny + iy) * nz + iz);
        const int count = mesh.FieldAt({ix, iy, iz}, &field);
        for (int c = 0; c < 3; ++c) {
          for (int i = 0; i < count; ++i) {
            const int dof = mesh.Dof(field[i].independent, c);
            if (owner[dof] < 0) continue;  // a support: zero
            surface_.terms.push_back({owner[dof], slot_of(dof), field[i].weight});
          }
          surface_.term_start.push_back(static_cast<int>(surface_.terms.size()));
        }
      }
    }
  }
  for (auto& region : regions_) {
    region->surface = std::make_unique<SeqlockArray>(region->surface_dofs.size());
  }
}

void AsyncRegions::PublishSurface(Region& region) noexcept {
  // The request is read before the values: served ≥ r then means values from after r was made.
  const std::uint64_t request = surface_request_.load(std::memory_order_acquire);
  const Eigen::VectorXd& u = region.integrator->u();
  region.surface->Write([&](std::size_t i) { return u[region.surface_dofs[i]]; });
  region.surface_request_served = request;
  region.surface_served.store(request, std::memory_order_release);
}

std::uint64_t AsyncRegions::RequestSurface() noexcept {
  return surface_request_.fetch_add(1, std::memory_order_acq_rel) + 1;
}

bool AsyncRegions::SurfaceServed(std::uint64_t request) const noexcept {
  return std::all_of(regions_.begin(), regions_.end(), [&](const auto& region) {
    return region->surface_served.load(std::memory_order_acquire) >= request;
  });
}

std::uint64_t AsyncRegions::surface_publications(RegionIndex region) const noexcept {
  return regions_[region]->surface->writes();
}

bool AsyncRegions::ReadSurface(std::vector<double>* displacement_m) const {
  constexpr int kAttempts = 64;
  std::vector<std::vector<double>> parts(regions_.size());
  for (size_t a = 0; a < regions_.size(); ++a) {
    const SeqlockArray& published = *regions_[a]->surface;
    parts[a].resize(published.size());
    int attempt = 0;
    while (!published.TryRead(parts[a].data())) {
      if (++attempt == kAttempts) return false;
    }
  }
  displacement_m->assign(surface_.term_start.size() - 1, 0.0);
  for (size_t v = 0; v + 1 < surface_.term_start.size(); ++v) {
    double sum = 0;
    for (int t = surface_.term_start[v]; t < surface_.term_start[v + 1]; ++t) {
      const SurfaceTerm& term = surface_.terms[t];
      sum += term.weight * parts[term.region][term.slot];
    }
    (*displacement_m)[v] = sum;
  }
  return true;
}

}  // namespace hapticsim
