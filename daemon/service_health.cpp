#include "daemon/service_health.hpp"

#include <spdlog/spdlog.h>

#include <optional>
#include <string>

namespace hapticsim {

ServiceHealth::ServiceHealth(HapticLoop& loop, const SystemdNotifier& systemd,
                             std::int64_t start_ns)
    : loop_(loop),
      systemd_(systemd),
      primary_period_s_(loop.monitor(kPrimaryRegion).TakeSnapshot().period_s),
      regions_since_ns_(start_ns),
      next_watchdog_ns_(start_ns) {}

std::vector<Stall> ServiceHealth::Stalled(std::int64_t now, const Signs& signs) {
  const bool asleep = loop_.asleep();  // read once: a wake between two reads would be missed
  if (loop_.reconfigurations() != reconfigurations_seen_ || (asleep_ && !asleep)) {
    regions_since_ns_ = now;
    reconfigurations_seen_ = loop_.reconfigurations();
  }
  asleep_ = asleep;
  return StalledThreads(HealthBeats(loop_, primary_period_s_, signs.io_alive_ns, regions_since_ns_,
                                    asleep, signs.choice_since_ns, signs.check_since_ns),
                        now);
}

void ServiceHealth::Report(std::int64_t now, const std::vector<Stall>& stalls) {
  if (const std::optional<std::string> stalled = stall_report_.Due(stalls, now)) {
    if (stalled->empty()) {
      spdlog::info("health: every thread runs again");
    } else {
      spdlog::error("health: stalled: {}{}", *stalled,
                    AnyOnForcePath(stalls) ? "; the systemd watchdog is not pinged" : "");
    }
    systemd_.Notify(stalled->empty() ? "STATUS=serving" : "STATUS=stalled: " + *stalled);
  }
  if (systemd_.watchdog_interval_s() > 0 && now >= next_watchdog_ns_ && !AnyOnForcePath(stalls)) {
    systemd_.Notify("WATCHDOG=1");
    next_watchdog_ns_ = now + static_cast<std::int64_t>(systemd_.watchdog_interval_s() * 0.5e9);
  }
}

}  // namespace hapticsim
