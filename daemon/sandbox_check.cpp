#include "daemon/sandbox_check.hpp"

#include <ifaddrs.h>
#include <net/if.h>

#include <cerrno>
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
    if ((i->ifa_flags & IFF_LOOPBACK) == 0) others.insert(i->ifa_name);
  }
  freeifaddrs(list);
  if (others.empty()) return "";
  std::string names;
  for (const auto& name : others) names += (names.empty() ? "" : ", ") + name;
  return "this network namespace has interfaces besides loopback (" + names +
         "): it is a host where a real device may be in use. Run it under `hapticsim soak "
         "--no-port-guard` or in a private network namespace (tests/support/in_private_netns.sh)";
}

}  // namespace hapticsim
