#pragma once
// Starting LCM so that a failure is an error that says what to fix, not a crash.
//
// lcm::LCM::good() is true as soon as LCM's udpm provider has its send socket; its receive side,
// with a self test that sends one message to the group and waits up to 10 s for it, is set up on
// first use. When that self test fails (the packets are dropped on the way back, e.g. by the
// systemd unit's IP filter when they leave with source 0.0.0.0 from a route on lo without
// `src 127.0.0.1`), the instance has no receive socket and a subscribe's queue capacity is set on
// a null subscription inside liblcm: a segmentation fault. getFileno() sets the receive side up
// now and returns -1 when it failed, so every LCM user in hapticsim calls this first.
#include <lcm/lcm-cpp.hpp>
#include <string>

namespace hapticsim {

/** The route LCM's default udpm:// group needs on a host, with the source address the systemd
 *  unit's IP filter (IPAddressAllow=localhost multicast) admits. */
inline constexpr const char* kLcmLoopbackRoute =
    "ip route replace 224.0.0.0/4 dev lo src 127.0.0.1";

/** "" when `lcm` can send and receive, else what went wrong and what to do. */
inline std::string LcmStartProblem(lcm::LCM& lcm, const std::string& url) {
  if (!lcm.good()) {
    return "LCM could not start on " + url +
           " (for udpm:// the interface needs a multicast route: " + kLcmLoopbackRoute +
           "; or set another LCM URL)";
  }
  // The receive side only udpm:// sets up on first use (and "" is udpm's default); tcpq://
  // connects when it can and reconnects by itself, memq:// and file:// always have a descriptor.
  const bool udpm = url.empty() || url.rfind("udpm://", 0) == 0 || url.rfind("mpudpm://", 0) == 0;
  if (udpm && lcm.getFileno() < 0) {
    return "LCM on " + url +
           " cannot receive: its self test's message did not come back (multicast dropped on the "
           "way: under the systemd unit, route the group through loopback with source "
           "127.0.0.1: " +
           kLcmLoopbackRoute + ")";
  }
  return "";
}

}  // namespace hapticsim
