// Carrying the object's motion from one configuration of the regions to another
// (AsyncRegions::CaptureState, AsyncRegions::RestoreState): prolongation onto the fine lattice,
// then injection into the new configuration's nodes; AsyncRegions::StartFrom, which SetRandomState
// shares, starts the regions from such a state. See docs/regions.md, "Switching in contact".
#include <Eigen/Core>
#include <algorithm>
#include <string>

#include "core/async_regions.hpp"
#include "core/async_regions_region.hpp"
#include "core/error.hpp"

namespace hapticsim {
namespace {

// Fills the lattice from the mesh's independent values: a lattice point with an independent node
// takes its value; any other lies in a coarse cell that was not refined (or on its face, a
// hanging node), where the mesh's displacement is the cell's trilinear field of its vertices —
// which are always independent nodes. A point on a face shared with a refined cell gets the same
// value from either cell: the field there depends on the face's four vertices alone.
void Prolong(const HybridMesh& mesh, const Eigen::VectorXd& values, std::vector<double>* lattice) {
  const int n = mesh.options().nodes_per_axis;
  const int k = mesh.options().coarse_factor;
  const int last_cell = (n - 1) / k - 1;
  lattice->assign(static_cast<size_t>(3) * n * n * n, 0.0);
  ObjectState index;
  index.nodes_per_axis = n;
  for (int ix = 0; ix < n; ++ix) {
    for (int iy = 0; iy < n; ++iy) {
      for (int iz = 0; iz < n; ++iz) {
        double* out = lattice->data() + index.Index(ix, iy, iz);
        if (const int node = mesh.IndependentAt(ix, iy, iz); node >= 0) {
          for (int c = 0; c < 3; ++c) out[c] = values[mesh.Dof(node, c)];
          continue;
        }
        const std::array<int, 3> p{ix, iy, iz};
        std::array<int, 3> cell;
        std::array<double, 3> t;
        for (int d = 0; d < 3; ++d) {
          cell[d] = std::min(p[d] / k, last_cell);
          t[d] = static_cast<double>(p[d] - cell[d] * k) / k;
        }
        for (int corner = 0; corner < 8; ++corner) {
          double weight = 1;
          std::array<int, 3> vertex;
          for (int d = 0; d < 3; ++d) {
            const int up = (corner >> d) & 1;
            vertex[d] = (cell[d] + up) * k;
            weight *= up ? t[d] : 1 - t[d];
          }
          const int node = mesh.IndependentAt(vertex[0], vertex[1], vertex[2]);
          HAPTICSIM_THROW_UNLESS(node >= 0, "internal: a coarse vertex is not a mesh node");
          for (int c = 0; c < 3; ++c) out[c] += weight * values[mesh.Dof(node, c)];
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
  state.nodes_per_axis = mesh.options().nodes_per_axis;
  Prolong(mesh, u, &state.displacement_m);
  Prolong(mesh, v, &state.velocity_m_per_s);
  return state;
}

void AsyncRegions::RestoreState(const ObjectState& state) {
  const HybridMesh& mesh = partition_.mesh();
  const int n = mesh.options().nodes_per_axis;
  const size_t size = static_cast<size_t>(3) * n * n * n;
  if (state.nodes_per_axis != n || state.displacement_m.size() != size ||
      state.velocity_m_per_s.size() != size) {
    throw Error("a state of " + std::to_string(state.nodes_per_axis) +
                " nodes per axis cannot start regions of " + std::to_string(n));
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
