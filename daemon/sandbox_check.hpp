#pragma once

#include <string>

namespace hapticsim {

/**
 * Why this process may not switch a safety layer off for a test ("" when it may): it must run in
 * a network namespace of its own with nothing but loopback in it, as the soak and the daemon's
 * tests do (tests/support/in_private_netns.sh). A daemon on a host's network, where a real
 * device and its user are, is refused; the answer names the interfaces it saw.
 */
std::string WhyNotASandbox();

}  // namespace hapticsim
