#include "core/regions/proxy_following.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.hpp"

namespace hapticsim {

std::optional<LatticeIndex> ProxyWantsPrimaryAt(const ProxyContact& proxy,
                                                const LatticeIndex& centre,
                                                double spacing_m) noexcept {
  const std::array<double, 3> at = proxy.proxy_rest_m();
  bool far = false;
  for (int c = 0; c < 3; ++c)
    far = far || std::abs(at[c] / spacing_m - centre[c]) > kProxyFollowAfter;
  if (!far) return std::nullopt;
  const LatticeIndex nearest = proxy.NearestNode();
  if (!proxy.InsideFace(nearest)) return std::nullopt;
  return nearest;
}

void CheckPrimaryReachesTip(const Scene& scene, double spacing_m, double slack_nodes) {
  const double reach = std::max(1.0, scene.contact.radius_m / spacing_m);
  const int needed = static_cast<int>(std::ceil(reach) + std::ceil(slack_nodes)) + 1;
  HAPTICSIM_THROW_UNLESS(scene.adaptivity.primary_size >= needed,
                         "contact.radius = " + GetSceneValue(scene, "contact.radius") +
                             " m reaches " + std::to_string(reach) + " lattice spacings of " +
                             std::to_string(spacing_m) +
                             " m from the proxy, and the primary region follows the proxy" +
                             (slack_nodes > 0 ? std::string(" (on real threads, a follow takes "
                                                            "time while the tool slides on)")
                                              : std::string()) +
                             ": set "
                             "adaptivity.primary_size >= " +
                             std::to_string(needed));
}

}  // namespace hapticsim
