// Sleeping at rest (see HapticLoop's class comment): out of contact, once every region is within
// kRestTolerance_m of rest, the secondary threads park and the regions stop stepping until a touch.
#include "daemon/haptic_loop.hpp"

namespace hapticsim {

void HapticLoop::ForgetSleep() {
  parking_.Forget();
  sleep_state_ = kAwake;
  counters_.asleep.Set(false);
  counters_.idle.Set(false);
}

bool HapticLoop::SecondaryMayStep(RegionIndex region) noexcept {
  return parking_.MayStep(region, [&] { return regions_->RegionAtRest(region, kRestTolerance_m); });
}

void HapticLoop::WatchForRest(bool touched) noexcept {
  const int secondaries = regions_->num_regions() - 1;
  if (sleep_state_ == kAwake) {
    if (touched) {
      parking_.StopWatch();
      return;
    }
    if (parking_.watch() == 0) {
      parking_.StartWatch();
      return;
    }
    if (!regions_->RegionAtRest(kPrimaryRegion, kRestTolerance_m)) return;
    if (!parking_.AllAtRest(secondaries)) return;
    parking_.Park();
    sleep_state_ = kParking;
  }
  if (sleep_state_ == kParking) {
    if (!parking_.AllParked(secondaries)) return;
    parking_.StopWatch();
    // Every region is parked, so their states can be read here: the tool may have touched and
    // left while they were parking (the primary stepped on meanwhile), and that deformation must
    // not be thrown away.
    bool at_rest = !touched;
    for (int a = 0; a <= secondaries && at_rest; ++a) {
      at_rest = regions_->RegionAtRest(a, kRestTolerance_m);
    }
    if (!at_rest) {
      WakeSecondaries(-1);  // they carry on where they were
      return;
    }
    // Nothing steps any region now: rest exactly, at time 0 of a schedule that starts on waking.
    regions_->Reset();
    RestartEnergyWatch();  // they start again from rest
    counters_.interface_backlog_j.Set(0);
    sleep_state_ = kAsleep;
    counters_.asleep.Set(true);
    counters_.sleeps.Add();
  }
}

void HapticLoop::WakeSecondaries(std::int64_t origin_ns) noexcept {
  parking_.Wake(origin_ns);
  sleep_state_ = kAwake;
  counters_.asleep.Set(false);
}

}  // namespace hapticsim
