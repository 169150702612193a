#include "daemon/sandbox_check.hpp"

#include <ifaddrs.h>
#include <net/if.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <set>

namespace hapticsim {

std::string WhyNotASandbox() {
  ifaddrs* list = nullptr;
  if (getifaddrs(&list) != 0) {
    return std::string("its network interfaces could not be listed (") + std::strerror(errno) + ")";
  }
  std::set<std::string> others;
  for (const ifaddrs* i = list; i != nullptr; i = i->ifa_next) {
    // Down interfaces carry nothing (a new namespace may hold fallback tunnels, all down).
    if ((i->ifa_flags & IFF_LOOPBACK) == 0 && (i->ifa_flags & IFF_UP) != 0) {
      others.insert(i->ifa_name);
    }
  }
  freeifaddrs(list);
  if (others.empty()) {
    // Shared memory reaches drivers on the host through a socket path whatever the namespace:
    // the soak and the tests say too that they started this daemon.
    const char* marker = std::getenv(kSandboxVariable);
    if (marker != nullptr && std::string(marker) == "1") return "";
    return std::string(
               "a private network namespace is not enough: shared-memory drivers on the "
               "host can still connect. The soak and the tests set ") +
           kSandboxVariable + "=1 for the daemons they start";
  }
  std::string names;
  for (const auto& name : others) names += (names.empty() ? "" : ", ") + name;
  return "this network namespace has interfaces up besides loopback (" + names +
         "): it is a host where a real device may be in use. Run it under `hapticsim soak "
         "--no-port-guard`, or in a private network namespace (tests/support/in_private_netns.sh) "
         "with " +
         std::string(kSandboxVariable) + "=1";
}

}  // namespace hapticsim
