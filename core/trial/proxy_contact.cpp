#include "core/trial/proxy_contact.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/error.hpp"

namespace hapticsim {

ProxySurface ProxySurfaceOf(const ElasticModel& model) {
  const HexGrid& grid = model.grid();
  ProxySurface surface;
  surface.lattice_nodes = {grid.nx(), grid.ny(), grid.nz()};
  surface.spacing_m = grid.spacing();
  const MaterialField& field = model.field();
  surface.occupied.resize(static_cast<std::size_t>(field.num_elements()));
  for (int e = 0; e < field.num_elements(); ++e) surface.occupied[e] = field.occupied(e) ? 1 : 0;
  std::vector<bool> held(static_cast<std::size_t>(grid.num_dofs()), false);
  for (int dof : model.constraints().fixed_dofs) held[static_cast<std::size_t>(dof)] = true;
  const auto nodes = static_cast<std::size_t>(grid.num_nodes());
  surface.dof.assign(nodes, -1);
  surface.loadable.assign(nodes, -1);
  surface.mass_kg.assign(nodes, 0.0);
  surface.component_stride = grid.num_nodes();
  for (int node = 0; node < grid.num_nodes(); ++node) {
    const int dof = grid.Dof(node, 0);
    const double mass = model.dof_mass()[dof];
    if (mass <= 0) continue;  // not the object's
    surface.dof[node] = dof;
    surface.mass_kg[node] = mass;
    surface.loadable[node] = held[static_cast<std::size_t>(dof)] ? 0 : 1;
  }
  return surface;
}

ProxyContact::ProxyContact(const ElasticModel& model, int contact_node,
                           const std::array<double, 3>& inward_normal,
                           const ContactSettings& contact)
    : ProxyContact(ProxySurfaceOf(model), model.grid().NodeIndices(contact_node), inward_normal,
                   contact) {}

ProxyContact::ProxyContact(ProxySurface surface, const LatticeIndex& contact_node,
                           const std::array<double, 3>& inward_normal,
                           const ContactSettings& contact)
    : contact_(contact) {
  axis_ = -1;
  for (int c = 0; c < 3; ++c) {
    if (std::abs(inward_normal[c]) == 1.0) {
      axis_ = c;
      sign_ = inward_normal[c] > 0 ? 1 : -1;
    }
  }
  HAPTICSIM_THROW_UNLESS(axis_ >= 0,
                         "a stroke starts on a flat face: choose an input.contact_node whose "
                         "inward normal is along x, y or z (not on an edge or a corner)");
  t1_ = (axis_ + 1) % 3;
  t2_ = (axis_ + 2) % 3;
  plane_ = contact_node[axis_];
  proxy_ = {static_cast<double>(contact_node[t1_]), static_cast<double>(contact_node[t2_])};
  for (int c = 0; c < 3; ++c) start_m_[c] = contact_node[c] * surface.spacing_m;
  reach_ = std::max(1.0, contact.radius_m / surface.spacing_m);
  if (reach_ > kMaxReach) {
    throw Error("contact.radius = " + std::to_string(contact.radius_m) + " m is " +
                std::to_string(reach_) + " lattice spacings of " +
                std::to_string(surface.spacing_m) + " m; a tool tip may reach at most " +
                std::to_string(kMaxReach) + ": lower contact.radius");
  }
  Rebind(std::move(surface));
}

void ProxyContact::Rebind(ProxySurface surface) {
  HAPTICSIM_THROW_UNLESS(
      surface_.num_nodes() == 0 || surface.lattice_nodes == surface_.lattice_nodes,
      "internal: a proxy moved onto another lattice");
  surface_ = std::move(surface);
  pushed_.count = 0;
  // Every node of the face's plane the surface lets the proxy push may be loaded.
  loaded_dofs_.clear();
  slot_of_node_.assign(static_cast<std::size_t>(surface_.num_nodes()), -1);
  lightest_mass_kg_ = std::numeric_limits<double>::infinity();
  const int stride = surface_.component_stride;
  for (int node = 0; node < surface_.num_nodes(); ++node) {
    const std::array<int, 3>& n = surface_.lattice_nodes;
    const std::array<int, 3> at = {node % n[0], node / n[0] % n[1], node / (n[0] * n[1])};
    const int along = at[axis_];
    if (along != plane_ || surface_.loadable[static_cast<std::size_t>(node)] != 1) continue;
    slot_of_node_[static_cast<std::size_t>(node)] = static_cast<int>(loaded_dofs_.size() / 3);
    for (int c = 0; c < 3; ++c) loaded_dofs_.push_back(surface_.dof[node] + c * stride);
    lightest_mass_kg_ = std::min(lightest_mass_kg_, surface_.mass_kg[node]);
  }
}

bool ProxyContact::Occupied(int along, int i1, int i2) const {
  const std::array<int, 3>& n = surface_.lattice_nodes;
  const std::array<int, 3> counts = {n[0] - 1, n[1] - 1, n[2] - 1};
  if (i1 < 0 || i2 < 0 || i1 >= counts[t1_] || i2 >= counts[t2_]) return false;
  if (along < 0 || along >= counts[axis_]) return false;
  std::array<int, 3> e{};
  e[axis_] = along;
  e[t1_] = i1;
  e[t2_] = i2;
  return surface_
             .occupied[static_cast<std::size_t>(e[0] + counts[0] * (e[1] + counts[1] * e[2]))] != 0;
}

bool ProxyContact::ExposedFace(int i1, int i2) const {
  // The voxel inside the face must be the object's, the one outside it not.
  const int inside = sign_ > 0 ? plane_ : plane_ - 1;
  const int outside = sign_ > 0 ? plane_ - 1 : plane_;
  return Occupied(inside, i1, i2) && !Occupied(outside, i1, i2);
}

std::array<int, 2> ProxyContact::CellOf(const std::array<double, 2>& proxy) const {
  const std::array<int, 3>& n = surface_.lattice_nodes;
  // A proxy exactly on the lattice's last node line belongs to the cell below it.
  const auto cell = [](double at, int count) {
    const int i = static_cast<int>(std::floor(at));
    return i == count && at == count ? count - 1 : i;
  };
  return {cell(proxy[0], n[t1_] - 1), cell(proxy[1], n[t2_] - 1)};
}

bool ProxyContact::PatchAt(const std::array<double, 2>& proxy, Patch* corners) const {
  const std::array<int, 2> cell = CellOf(proxy);
  const int i1 = cell[0], i2 = cell[1];
  if (!std::isfinite(proxy[0] + proxy[1]) || !ExposedFace(i1, i2)) return false;
  if (reach_ > 1.0) return TentPatch(proxy, corners);
  const double a = proxy[0] - i1, b = proxy[1] - i2;
  corners->count = 4;
  for (int k = 0; k < 4; ++k) {
    std::array<int, 3> at{};
    at[axis_] = plane_;
    at[t1_] = i1 + (k & 1);
    at[t2_] = i2 + (k >> 1);
    corners->nodes[static_cast<std::size_t>(k)] = surface_.Node(at);
    corners->weights[static_cast<std::size_t>(k)] = ((k & 1) ? a : 1 - a) * ((k >> 1) ? b : 1 - b);
  }
  return true;
}

// A tip wider than a cell: every face node within reach_ of the proxy along both tangents, weighted
// (1 − |Δ1|/r)(1 − |Δ2|/r) (r = reach_ in spacings), the weights normalised to sum 1.
bool ProxyContact::TentPatch(const std::array<double, 2>& proxy, Patch* patch) const {
  const std::array<int, 3>& n = surface_.lattice_nodes;
  const int lo1 = std::max(0, static_cast<int>(std::ceil(proxy[0] - reach_)));
  const int hi1 = std::min(n[t1_] - 1, static_cast<int>(std::floor(proxy[0] + reach_)));
  const int lo2 = std::max(0, static_cast<int>(std::ceil(proxy[1] - reach_)));
  const int hi2 = std::min(n[t2_] - 1, static_cast<int>(std::floor(proxy[1] + reach_)));
  patch->count = 0;
  double sum = 0;
  for (int i2 = lo2; i2 <= hi2; ++i2) {
    for (int i1 = lo1; i1 <= hi1; ++i1) {
      const double w =
          (1.0 - std::abs(i1 - proxy[0]) / reach_) * (1.0 - std::abs(i2 - proxy[1]) / reach_);
      std::array<int, 3> at{};
      at[axis_] = plane_;
      at[t1_] = i1;
      at[t2_] = i2;
      // The face's nodes: a corner of one of its exposed cells (one with no displacement in this
      // state vector, hanging on another region's cells, makes the patch unreadable).
      if (!(w > 0) || !OnFace(i1, i2, /*every=*/false)) continue;
      const int node = surface_.Node(at);
      patch->nodes[static_cast<std::size_t>(patch->count)] = node;
      patch->weights[static_cast<std::size_t>(patch->count)] = w;
      ++patch->count;
      sum += w;
    }
  }
  for (int k = 0; k < patch->count; ++k) patch->weights[static_cast<std::size_t>(k)] /= sum;
  return patch->count > 0;
}

bool ProxyContact::Readable(const Patch& patch) const {
  for (int k = 0; k < patch.count; ++k) {
    if (surface_.dof[static_cast<std::size_t>(patch.nodes[static_cast<std::size_t>(k)])] < 0)
      return false;
  }
  return true;
}

bool ProxyContact::OnFace(int i1, int i2, bool every) const {
  int exposed = 0;
  for (int k = 0; k < 4; ++k) exposed += ExposedFace(i1 - 1 + (k & 1), i2 - 1 + (k >> 1)) ? 1 : 0;
  return every ? exposed == 4 : exposed > 0;
}

bool ProxyContact::InsideFace(const LatticeIndex& node) const {
  return node[axis_] == plane_ && OnFace(node[t1_], node[t2_], /*every=*/true);
}

bool ProxyContact::Reachable(const Patch& patch) const {
  for (int k = 0; k < patch.count; ++k) {
    if (surface_.loadable[static_cast<std::size_t>(patch.nodes[static_cast<std::size_t>(k)])] < 0)
      return false;
  }
  return true;
}

std::array<double, 3> ProxyContact::SurfacePoint(const Patch& corners,
                                                 const Eigen::VectorXd& u) const {
  std::array<double, 3> point = proxy_rest_m();
  for (int k = 0; k < corners.count; ++k) {
    const int dof =
        surface_.dof[static_cast<std::size_t>(corners.nodes[static_cast<std::size_t>(k)])];
    const double w = corners.weights[static_cast<std::size_t>(k)];
    for (int c = 0; c < 3; ++c) point[c] += w * u[dof + c * surface_.component_stride];
  }
  return point;
}

bool ProxyContact::CanTouchAt(const std::array<double, 3>& tool_m) const noexcept {
  Patch patch;
  const double h = surface_.spacing_m;
  return PatchAt({tool_m[t1_] / h, tool_m[t2_] / h}, &patch) && Readable(patch) && Reachable(patch);
}

bool ProxyContact::ContinueFrom(const ProxyContact& other) noexcept {
  if (other.axis_ != axis_ || other.sign_ != sign_ || other.plane_ != plane_) return false;
  proxy_ = other.proxy_;
  last_tool_ = other.last_tool_;
  sliding_ = other.sliding_;
  wall_held_ = other.wall_held_;
  let_go_ = other.let_go_;
  last_depth_m_ = other.last_depth_m_;
  return true;
}

void ProxyContact::PlaceUnder(const std::array<double, 3>& tool_m) noexcept {
  proxy_ = {tool_m[t1_] / surface_.spacing_m, tool_m[t2_] / surface_.spacing_m};
  last_tool_ = proxy_;
  sliding_ = false;
  ForgetWalls();
}

std::array<double, 3> ProxyContact::proxy_rest_m() const {
  const double h = surface_.spacing_m;
  std::array<double, 3> rest{};
  rest[axis_] = plane_ * h;
  rest[t1_] = proxy_[0] * h;
  rest[t2_] = proxy_[1] * h;
  return rest;
}

LatticeIndex ProxyContact::NearestNode() const {
  LatticeIndex at{};
  at[axis_] = plane_;
  at[t1_] =
      std::clamp(static_cast<int>(std::lround(proxy_[0])), 0, surface_.lattice_nodes[t1_] - 1);
  at[t2_] =
      std::clamp(static_cast<int>(std::lround(proxy_[1])), 0, surface_.lattice_nodes[t2_] - 1);
  return at;
}

double ProxyContact::Compliance(const Patch& patch,
                                std::span<const double> compliance) const noexcept {
  double sum = 0;
  for (int k = 0; k < patch.count; ++k) {
    const auto j = static_cast<std::size_t>(k);
    const int slot = slot_of_node_[static_cast<std::size_t>(patch.nodes[j])];
    if (slot >= 0) sum += patch.weights[j] * patch.weights[j] * compliance[3 * slot];
  }
  return sum;
}

ProxyContact::Result ProxyContact::Update(const std::array<double, 3>& tool_m,
                                          const Eigen::VectorXd& u,
                                          std::span<const double> compliance,
                                          std::span<double> loads) noexcept {
  std::fill(loads.begin(), loads.end(), 0.0);
  // Off the face the spread of the last push is kept: a caller fading that push out spreads it
  // there (SpreadLoads).
  const int last_pushed = pushed_.count;
  pushed_.count = 0;
  Result result;
  Patch corners;
  const double h = surface_.spacing_m;
  const std::array<double, 2> tool = {tool_m[t1_] / h, tool_m[t2_] / h};  // node spacings
  const double tool_moved_m = std::hypot(tool[0] - last_tool_[0], tool[1] - last_tool_[1]) * h;
  last_tool_ = tool;
  const auto offset_to_tool = [&] {
    const std::array<double, 3> s = SurfacePoint(corners, u);
    return std::array<double, 3>{tool_m[0] - s[0], tool_m[1] - s[1], tool_m[2] - s[2]};
  };
  // Over no face of the object, the tool has left the surface this contact can render. Over a
  // wall rising from the face (a concave corner) it has not: the wall holds the proxy at its foot.
  if (!OverFaceOrWall(tool) || !PatchAt(proxy_, &corners)) {
    result.left_surface = true;
    pushed_.count = last_pushed;
    return result;
  }
  if (!Readable(corners)) {
    result.left_region = true;
    ForgetWalls();
    return result;
  }
  std::array<double, 3> d = offset_to_tool();
  const double depth = sign_ * d[axis_];
  if (depth <= 0 && LetGoAboveTheFace(tool_m, &result)) {
    pushed_.count = last_pushed;
    return result;
  }
  if (depth <= 0) {  // out of contact: the proxy waits under the tool
    proxy_ = tool;
    sliding_ = false;
    ForgetWalls();
    return result;
  }
  if (!Reachable(corners)) {  // in contact where this surface cannot push
    result.left_region = true;
    ForgetWalls();
    return result;
  }
  const double shed_m = std::max(0.0, last_depth_m_ - depth);  // (NaN before: none)
  last_depth_m_ = depth;
  if (SlideByFriction(d, depth, tool_moved_m + contact_.kinetic_friction * shed_m, corners,
                      compliance)) {
    if (!PatchAt(proxy_, &corners)) {
      result.left_surface = true;
      pushed_.count = last_pushed;
      return result;
    }
    if (!Readable(corners) || !Reachable(corners)) {
      result.left_region = true;
      ForgetWalls();
      return result;
    }
    d = offset_to_tool();
  }
  result.in_contact = true;
  result.sliding = sliding_;
  Push(corners, d, compliance, loads, &result);
  return result;
}

void ProxyContact::Push(const Patch& corners, const std::array<double, 3>& d,
                        std::span<const double> compliance, std::span<double> loads,
                        Result* result) noexcept {
  result->offset_m = d;
  // What a wall held as this slide began is still the wall's, and what it let go of while the
  // proxy catches up (SlideByFriction): the proxy sliding past a wall's end has left it by now.
  for (int t = 0; t < 2; ++t) {
    const auto j = static_cast<std::size_t>(t);
    result->wall_holds[static_cast<std::size_t>(t == 0 ? t1_ : t2_)] =
        AgainstWall(t, d[t == 0 ? t1_ : t2_]) || wall_held_[j] || let_go_[j];
  }
  // The spring taken at the step's end: the push f moves the surface under the proxy by C·f, so
  // f = k·(d − C·f).
  const double k = contact_.stiffness_n_per_m;
  result->compliance_m_per_n = Compliance(corners, compliance);
  for (int c = 0; c < 3; ++c)
    result->force_on_object_n[c] = k * d[c] / (1.0 + k * result->compliance_m_per_n);
  pushed_.count = corners.count;  // (only the entries in use: a patch holds up to 289)
  std::copy_n(corners.nodes.begin(), corners.count, pushed_.nodes.begin());
  std::copy_n(corners.weights.begin(), corners.count, pushed_.weights.begin());
  SpreadLoads(result->force_on_object_n, loads);
}

void ProxyContact::SpreadLoads(const std::array<double, 3>& force_on_object_n,
                               std::span<double> loads) const noexcept {
  std::fill(loads.begin(), loads.end(), 0.0);
  for (int j = 0; j < pushed_.count; ++j) {
    const int slot =
        slot_of_node_[static_cast<std::size_t>(pushed_.nodes[static_cast<std::size_t>(j)])];
    if (slot < 0) continue;  // a held node: the support takes that share
    for (int c = 0; c < 3; ++c) {
      loads[static_cast<std::size_t>(3 * slot + c)] =
          pushed_.weights[static_cast<std::size_t>(j)] * force_on_object_n[c];
    }
  }
}

}  // namespace hapticsim
