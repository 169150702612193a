#pragma once

#include <optional>

#include "core/scene/scene.hpp"
#include "core/trial/proxy_contact.hpp"

namespace hapticsim {

/**
 * How the primary region follows a sliding proxy across the face — the same rule offline
 * (RunRegionStroke) and in hapticsimd (SlidingContact).
 *
 * The primary is centred on a node of the face. The proxy may leave it by kProxyFollowAfter nodes
 * along a tangent before the regions move onto the node nearest it: a band above the half node a
 * move leaves it at, so a proxy sliding along a node line does not move the regions to and fro.
 */
inline constexpr double kProxyFollowAfter = 0.75;  // nodes

/**
 * The node the primary should move onto, centred on `centre` now: the node nearest the proxy,
 * once the proxy is more than kProxyFollowAfter nodes from the centre and that node is inside the
 * face (its inward normal the face's; at the rim the primary stays, and a proxy that goes on
 * reaches the face's edge). None otherwise. Never allocates.
 */
std::optional<LatticeIndex> ProxyWantsPrimaryAt(const ProxyContact& proxy,
                                                const LatticeIndex& centre,
                                                double spacing_m) noexcept;

/**
 * How far past kProxyFollowAfter the proxy may slide while hapticsimd's regions follow it, nodes:
 * on real threads a follow is built and installed on the supervisor's thread while the tool goes
 * on. (Measured on examples/organ at 5 mm voxels, a tip of two spacings stroked at 60 mm/s: on a
 * primary of 3 the tip slid off the primary before the follow landed, and its force fell to zero
 * at the slew ceiling and came back, at one move in three; on a primary of 4, none.)
 */
inline constexpr double kThreadsFollowSlack = 1.0;

/**
 * Throws unless the primary can follow the proxy's tip: it reaches r = max(1, contact.radius / h)
 * nodes from the proxy (the cell under it: 1), and a primary of ⌈r⌉ + 1 nodes keeps every node
 * the tip touches off its interface with a quarter node to spare for the proxy's slide in a
 * period, when a follow lands in the period it is asked for (offline). `slack_nodes` more for
 * the proxy's slide meanwhile where it takes longer (hapticsimd: kThreadsFollowSlack). The
 * message says which adaptivity.primary_size to set.
 */
void CheckPrimaryReachesTip(const Scene& scene, double spacing_m, double slack_nodes = 0);

}  // namespace hapticsim
