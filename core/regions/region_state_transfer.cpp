// Carrying the object's motion from one configuration of the regions to another
// (AsyncRegions::CaptureState, AsyncRegions::RestoreState): prolongation onto the fine lattice,
// then injection into the new configuration's nodes; AsyncRegions::StartFrom, which SetRandomState
// shares, starts the regions from such a state. See docs/regions.md, "Switching in contact".
#include <Eigen/Core>
#include <array>
#include <string>

#include "core/regions/async_regions.hpp"
#include "core/regions/async_regions_region.hpp"
#include "core/error.hpp"

namespace hapticsim {
namespace {

// Fills the lattice from the mesh's independent values (HybridMesh::FieldAt).
void Prolong(const HybridMesh& mesh, const Eigen::VectorXd& values, std::vector<double>* lattice) {
  ObjectState index;
  index.lattice_nodes = mesh.options().lattice_nodes;
  lattice->assign(3 * index.num_points(), 0.0);
  std::array<GatherTerm, 8> terms;
  for (int ix = 0; ix < index.lattice_nodes[0]; ++ix) {
    for (int iy = 0; iy < index.lattice_nodes[1]; ++iy) {
      for (int iz = 0; iz < index.lattice_nodes[2]; ++iz) {
        double* out = lattice->data() + index.Index(ix, iy, iz);
        const int count = mesh.FieldAt({ix, iy, iz}, &terms);
        for (int i = 0; i < count; ++i) {
          for (int c = 0; c < 3; ++c) out[c] += terms[i].weight * values[mesh.Dof(terms[i].independent, c)];
        }
      }
    }
  }
}

// The values of the mesh's independent nodes, each its lattice point's (injection).
Eigen::VectorXd Inject(const HybridMesh& mesh, const ObjectState& state,
                       const std::vector<double>& lattice) {
  Eigen::VectorXd values(mesh.num_dofs());
  for (int node = 0; node < mesh.num_independent(); ++node) {
    const std::array<int, 3>& p = mesh.LatticeOf(node);
    const size_t i = state.Index(p[0], p[1], p[2]);
    for (int c = 0; c < 3; ++c) values[mesh.Dof(node, c)] = lattice[i + c];
  }
  return values;
}

}  // namespace

ObjectState AsyncRegions::CaptureState() const {
  const HybridMesh& mesh = partition_.mesh();
  Eigen::VectorXd u = Eigen::VectorXd::Zero(mesh.num_dofs());
  Eigen::VectorXd v = Eigen::VectorXd::Zero(mesh.num_dofs());
  auto take = [&](const RegionIntegrator& integrator, int dof) {
    u[dof] = integrator.u()[dof];
    v[dof] = (integrator.u()[dof] - integrator.u_previous()[dof]) / integrator.substep();
  };
  for (int a = 0; a < num_regions(); ++a) {
    for (int dof : partition_.dofs(a).owned) take(*regions_[a]->integrator, dof);
  }
  // The contact is the primary's prescribed DOF; the supports stay zero.
  for (int dof : partition_.contact_dofs()) take(*regions_[kPrimaryRegion]->integrator, dof);
  ObjectState state;
  state.lattice_nodes = mesh.options().lattice_nodes;
  Prolong(mesh, u, &state.displacement_m);
  Prolong(mesh, v, &state.velocity_m_per_s);
  return state;
}

void AsyncRegions::RestoreState(const ObjectState& state) {
  const HybridMesh& mesh = partition_.mesh();
  const std::array<int, 3>& n = mesh.options().lattice_nodes;
  const size_t size = 3 * state.num_points();
  if (state.lattice_nodes != n || state.displacement_m.size() != size ||
      state.velocity_m_per_s.size() != size) {
    auto text = [](const std::array<int, 3>& m) {
      return std::to_string(m[0]) + " × " + std::to_string(m[1]) + " × " + std::to_string(m[2]);
    };
    throw Error("a state of a lattice of " + text(state.lattice_nodes) +
                " nodes cannot start regions of " + text(n));
  }
  StartFrom(Inject(mesh, state, state.displacement_m), Inject(mesh, state, state.velocity_m_per_s));
}

void AsyncRegions::StartFrom(const Eigen::VectorXd& u, const Eigen::VectorXd& v) {
  Reset();
  // Every copy holds the same displacements (each Γ included), each its own u⁻ for its substep;
  // each region reads only its own DOFs.
  for (auto& region : regions_) {
    region->integrator->SetState(u, u - region->integrator->substep() * v);
    if (region->inward) region->inward->Clear();
    if (region->outward) region->outward->Clear();
  }
  ResetEnergyAccount();
  PublishInitialSnapshots();
}

}  // namespace hapticsim
