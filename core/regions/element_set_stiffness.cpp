#include "core/regions/element_set_stiffness.hpp"

#include <algorithm>
#include <cstring>

#include "core/error.hpp"
#include "core/fem/cpu_dispatch.hpp"
#include "core/fem/stencil_kernels.hpp"

namespace hapticsim {

ElementSetStiffness::ElementSetStiffness(const HybridMesh& mesh,
                                         const std::vector<Material>& materials,
                                         std::vector<int> element_ids)
    : StiffnessOperator(mesh.num_dofs()), mesh_(mesh), element_ids_(std::move(element_ids)) {
  for (const Material& material : materials) {
    unit_stiffness_.push_back(Hex8Element::Stiffness(1.0, material));
  }
  for (int id : element_ids_) {
    HAPTICSIM_THROW_UNLESS(mesh.elements()[id].material < static_cast<int>(materials.size()),
                           "internal: an element's material is not among the materials");
  }
  std::vector<char> touched(static_cast<size_t>(mesh.num_independent()), 0);
  for (int id : element_ids_) {
    for (int node : mesh.elements()[id].nodes) {
      const auto [begin, end] = mesh.Gather(node);
      for (auto* g = begin; g != end; ++g) touched[g->independent] = 1;
    }
  }
  for (int c = 0; c < 3; ++c) {
    for (int r = 0; r < mesh.num_independent(); ++r) {
      if (touched[r]) touched_dofs_.push_back(mesh.Dof(r, c));
    }
  }
  direct_nodes_.reserve(element_ids_.size());
  for (int id : element_ids_) {
    std::array<int, 8> direct{};
    for (int local = 0; local < 8 && direct[0] >= 0; ++local) {
      const auto [begin, end] = mesh.Gather(mesh.elements()[id].nodes[local]);
      const bool plain = end - begin == 1 && begin->weight == 1.0;
      direct[local] = begin->independent;
      if (!plain) direct[0] = -1;
    }
    direct_nodes_.push_back(direct);
  }
}

HAPTICSIM_KERNEL_CLONES
void ElementSetStiffness::ApplyElements(const double* u, double* ku) const {
  static_assert(!Hex8Element::Matrix24::IsRowMajor, "MultiplyElement reads columns");
  for (int dof : touched_dofs_) ku[dof] = 0.0;
  const int nr = mesh_.num_independent();
  const double h = mesh_.options().spacing_m;
  double ue[24], fe[24];
  for (size_t k = 0; k < element_ids_.size(); ++k) {
    const HybridElement& e = mesh_.elements()[element_ids_[k]];
    const std::array<int, 8>& direct = direct_nodes_[k];
    if (direct[0] >= 0) {  // no hanging node: each node is one independent node
      for (int local = 0; local < 8; ++local) {
        for (int c = 0; c < 3; ++c) ue[3 * local + c] = u[c * nr + direct[local]];
      }
    } else {
      for (int local = 0; local < 8; ++local) {
        const auto [begin, end] = mesh_.Gather(e.nodes[local]);
        double x = 0, y = 0, z = 0;
        for (auto* g = begin; g != end; ++g) {
          x += g->weight * u[g->independent];
          y += g->weight * u[nr + g->independent];
          z += g->weight * u[2 * nr + g->independent];
        }
        ue[3 * local] = x;
        ue[3 * local + 1] = y;
        ue[3 * local + 2] = z;
      }
    }
    MultiplyElement24(unit_stiffness_[e.material].data(), ue, fe);
    const double scale = e.size_factor * h;
    for (double& f : fe) f *= scale;
    if (direct[0] >= 0) {
      for (int local = 0; local < 8; ++local) {
        for (int c = 0; c < 3; ++c) ku[c * nr + direct[local]] += fe[3 * local + c];
      }
      continue;
    }
    for (int local = 0; local < 8; ++local) {
      const auto [begin, end] = mesh_.Gather(e.nodes[local]);
      for (auto* g = begin; g != end; ++g) {
        ku[g->independent] += g->weight * fe[3 * local];
        ku[nr + g->independent] += g->weight * fe[3 * local + 1];
        ku[2 * nr + g->independent] += g->weight * fe[3 * local + 2];
      }
    }
  }
}

void ElementSetStiffness::Apply(const Eigen::Ref<const Eigen::VectorXd>& u,
                                Eigen::Ref<Eigen::VectorXd> ku) const {
  ApplyElements(u.data(), ku.data());
}

Eigen::VectorXd ElementSetStiffness::Diagonal() const {
  Eigen::VectorXd diagonal = Eigen::VectorXd::Zero(num_dofs());
  const int nr = mesh_.num_independent();
  const double h = mesh_.options().spacing_m;
  for (int id : element_ids_) {
    const HybridElement& e = mesh_.elements()[id];
    for (int a = 0; a < 8; ++a) {
      for (int b = 0; b < 8; ++b) {
        const auto [ba, ea] = mesh_.Gather(e.nodes[a]);
        const auto [bb, eb] = mesh_.Gather(e.nodes[b]);
        for (auto* ga = ba; ga != ea; ++ga) {
          for (auto* gb = bb; gb != eb; ++gb) {
            if (ga->independent != gb->independent) continue;
            for (int c = 0; c < 3; ++c) {
              diagonal[c * nr + ga->independent] += ga->weight * gb->weight * e.size_factor * h *
                                                    unit_stiffness_[e.material](3 * a + c, 3 * b + c);
            }
          }
        }
      }
    }
  }
  return diagonal;
}

}  // namespace hapticsim
