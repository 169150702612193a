// ProxyContact at walls rising from its face (a concave corner): where the proxy stops, what a
// wall holds of the spring's pull, the catch-up after a wall lets go, and the let-go above the
// face past a wall. The rest of the proxy: proxy_contact.cpp.
#include <algorithm>
#include <cmath>
#include <limits>

#include "core/trial/proxy_contact.hpp"

namespace hapticsim {

bool ProxyContact::WallCell(int i1, int i2) const {
  return Occupied(sign_ > 0 ? plane_ - 1 : plane_, i1, i2);
}

bool ProxyContact::OverFaceOrWall(const std::array<double, 2>& proxy) const {
  if (!std::isfinite(proxy[0] + proxy[1])) return false;
  const std::array<int, 2> cell = CellOf(proxy);
  return ExposedFace(cell[0], cell[1]) || WallCell(cell[0], cell[1]);
}

bool ProxyContact::AgainstWall(int tangent, double direction) const {
  if (direction == 0) return false;
  const std::array<int, 2> cell = CellOf(proxy_);
  const auto t = static_cast<std::size_t>(tangent);
  const double within = proxy_[t] - cell[t];  // (1 on the lattice's last node line)
  // Clamped, the proxy sits kWallGap short of the boundary ahead, or on the one behind.
  const bool at_boundary = direction > 0 ? within >= 1 - 2 * kWallGap : within <= kWallGap;
  std::array<int, 2> beyond = cell;
  beyond[t] += direction > 0 ? 1 : -1;
  return at_boundary && WallCell(beyond[0], beyond[1]);
}

void ProxyContact::SlideTowards(std::array<double, 2> target) noexcept {
  // In steps of at most half a cell, one tangent at a time: a step onto a wall's cell stops that
  // tangent at the boundary for good, the other goes on (the proxy slides along the wall's foot).
  // A target off the lattice is taken just off it (the proxy has left the surface either way).
  const std::array<int, 3>& n = surface_.lattice_nodes;
  for (int t = 0; t < 2; ++t) {
    const double last = n[t == 0 ? t1_ : t2_] - 1;
    if (!std::isfinite(target[t])) return;
    target[t] = std::clamp(target[t], -1.0, last + 1);
  }
  const double span = std::max(std::abs(target[0] - proxy_[0]), std::abs(target[1] - proxy_[1]));
  const int steps = std::max(1, static_cast<int>(std::ceil(2 * span)));
  const std::array<double, 2> from = proxy_;
  std::array<bool, 2> stopped{};
  for (int s = 1; s <= steps; ++s) {
    for (int t = 0; t < 2; ++t) {
      if (stopped[t]) continue;
      const double next = from[t] + (target[t] - from[t]) * s / steps;
      std::array<double, 2> moved = proxy_;
      moved[t] = next;
      const std::array<int, 2> cell = CellOf(moved), now = CellOf(proxy_);
      if (cell[t] != now[t] && WallCell(cell[0], cell[1])) {
        proxy_[t] = next > proxy_[t] ? now[t] + 1 - kWallGap : now[t];
        stopped[t] = true;
      } else {
        proxy_[t] = next;
      }
    }
  }
}

void ProxyContact::ForgetWalls() noexcept {
  wall_held_ = let_go_ = {};
  last_depth_m_ = std::numeric_limits<double>::quiet_NaN();
}

bool ProxyContact::SlideByFriction(const std::array<double, 3>& d, double depth, double tool_shed_m,
                                   const Patch& corners,
                                   std::span<const double> compliance) noexcept {
  // The pull into a wall the proxy is against is the wall's to hold, not friction's: only the
  // rest of the tangential pull may slide it.
  std::array<double, 2> pull = {d[t1_], d[t2_]};
  for (int t = 0; t < 2; ++t) {
    const bool held = AgainstWall(t, pull[static_cast<std::size_t>(t)]);
    // A wall that stops holding (the proxy slid along its foot past its end) gives the pull it
    // held back to friction: the proxy catches up (below).
    if (wall_held_[static_cast<std::size_t>(t)] && !held)
      let_go_[static_cast<std::size_t>(t)] = true;
    wall_held_[static_cast<std::size_t>(t)] = held;
    if (held) pull[static_cast<std::size_t>(t)] = 0;
  }
  const double tangential = std::hypot(pull[0], pull[1]);
  const double mu = sliding_ ? contact_.kinetic_friction : contact_.static_friction;
  sliding_ = tangential > mu * depth;
  if (!sliding_) {
    let_go_ = {};
    return false;
  }
  // Slide towards the tool until the pull is μ_k times the push, or a wall stops it. Catching up,
  // by at most what the tool's own motion sheds plus kSlideCatchUp_n of the force rendered (the
  // spring k in series with the surface's compliance C): at once, it stepped the force by 0.41 N
  // where a wall 6 mm deep ended.
  const double h = surface_.spacing_m;
  double move = (tangential - contact_.kinetic_friction * depth) / tangential;
  if (CatchingUp()) {
    const double k = contact_.stiffness_n_per_m;
    const double most_m =
        tool_shed_m + kSlideCatchUp_n * (1.0 + k * Compliance(corners, compliance)) / k;
    if (!(move * tangential > most_m)) {
      let_go_ = {};  // caught up
    } else if (std::isfinite(most_m)) {
      move = most_m / tangential;
    }
  }
  SlideTowards({proxy_[0] + move * pull[0] / h, proxy_[1] + move * pull[1] / h});
  return true;
}

bool ProxyContact::LetGoAboveTheFace(const std::array<double, 3>& tool_m,
                                     Result* result) const noexcept {
  // Above the face's plane (out of contact) past a wall's foot the proxy is held at, or over a
  // wall: the tool is in the wall, or past it over the face beyond (a ridge), which this face
  // cannot render (it renders the wall's push at the foot only while the tool is below the face
  // too). Out of contact at once, a push as deep as the tool is past the wall stepped to nothing
  // (1.98 N, 2 cm past a ridge): it is let go, fading.
  const double h = surface_.spacing_m;
  const std::array<double, 3> rest = proxy_rest_m();
  double past_held_wall_m = 0;
  std::array<double, 3> wall_inward{};  // the wall's face's: the way the tool went past its foot
  for (int t = 0; t < 2; ++t) {
    const int axis = t == 0 ? t1_ : t2_;
    const double past = tool_m[axis] - rest[axis];
    if (AgainstWall(t, past) && std::abs(past) > past_held_wall_m) {
      past_held_wall_m = std::abs(past);
      wall_inward = {};
      wall_inward[static_cast<std::size_t>(axis)] = past > 0 ? 1.0 : -1.0;
    }
  }
  const std::array<int, 2> cell = CellOf({tool_m[t1_] / h, tool_m[t2_] / h});
  const bool over_wall = WallCell(cell[0], cell[1]);
  // Catching up with a wall's push it let go of (SlideByFriction), the same.
  if (past_held_wall_m == 0 && !over_wall && !CatchingUp()) return false;
  result->left_surface = true;
  if (over_wall) {
    result->into_wall_m = past_held_wall_m;
    result->into_wall_inward = wall_inward;
  }
  return true;
}

}  // namespace hapticsim
