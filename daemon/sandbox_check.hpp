#pragma once

#include <string>

namespace hapticsim {

/**
 * Why this process may not switch a safety layer off for a test ("" when it may): it must run in
 * a network namespace of its own with no interface up but loopback, as the soak and the daemon's
 * tests do (tests/support/in_private_netns.sh), and with kSandboxVariable set to 1 by whoever
 * started it there. A daemon on a host's network, where a real device and its user are, is
 * refused; the answer names the interfaces it saw. (A user who sets both by hand has decided to;
 * the daemon's log and status still say the guard is off.)
 */
std::string WhyNotASandbox();

/** Set to 1 by the soak (and tests) for the daemons they start in their own namespace. */
inline constexpr const char* kSandboxVariable = "HAPTICSIM_SANDBOX";

}  // namespace hapticsim
