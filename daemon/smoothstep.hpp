#pragma once
// The blend the contact's ramps and catch-ups share.

namespace hapticsim {

/** 3τ² − 2τ³ for τ in [0, 1]: from 0 to 1 with zero slope at both ends, so that what it blends
 *  starts and ends without a jump in its rate (a velocity jump of a driven node is a force spike).
 */
constexpr double Smoothstep(double tau) noexcept { return tau * tau * (3 - 2 * tau); }

}  // namespace hapticsim
