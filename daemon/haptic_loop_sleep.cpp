// Sleeping at rest (see HapticLoop's class comment): out of contact, once every region is within
// kRestTolerance_m of rest, the secondary threads park and the regions stop stepping until a touch.
#include "rt/futex.hpp"
#include "daemon/haptic_loop.hpp"

namespace hapticsim {

void HapticLoop::ForgetSleep() {
  park_secondaries_.store(false);
  watch_.store(0);
  for (auto& parked : parked_) parked.store(false);
  wake_origin_ns_.store(-1);
  sleep_state_ = kAwake;
  asleep_.store(false);
  idle_.store(false);
}

bool HapticLoop::SecondaryMayStep(RegionIndex region) noexcept {
  if (park_secondaries_.load(std::memory_order_acquire)) {
    parked_[region].store(true, std::memory_order_release);  // publishes its last step's writes
    return false;
  }
  const std::uint32_t watch = watch_.load(std::memory_order_acquire);
  if (watch != 0 && regions_->RegionAtRest(region, kRestTolerance_m)) {
    at_rest_in_watch_[region].store(watch, std::memory_order_release);
  }
  return true;
}

void HapticLoop::WatchForRest(bool touched) noexcept {
  const int secondaries = regions_->num_regions() - 1;
  if (sleep_state_ == kAwake) {
    if (touched) {
      watch_.store(0, std::memory_order_relaxed);
      return;
    }
    const std::uint32_t watch = watch_.load(std::memory_order_relaxed);
    if (watch == 0) {
      watches_ = watches_ == UINT32_MAX ? 1 : watches_ + 1;
      watch_.store(watches_, std::memory_order_release);
      return;
    }
    if (!regions_->RegionAtRest(kPrimaryRegion, kRestTolerance_m)) return;
    for (int a = 1; a <= secondaries; ++a) {
      if (at_rest_in_watch_[a].load(std::memory_order_acquire) != watch) return;
    }
    park_secondaries_.store(true, std::memory_order_release);
    sleep_state_ = kParking;
  }
  if (sleep_state_ == kParking) {
    for (int a = 1; a <= secondaries; ++a) {
      if (!parked_[a].load(std::memory_order_acquire)) return;
    }
    watch_.store(0, std::memory_order_relaxed);
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
    balance_peak_stored_j_ = 0;  // they start again from rest
    runaway_seen_ = false;
    runaway_periods_ = 0;
    interface_backlog_j_.store(0, std::memory_order_relaxed);
    sleep_state_ = kAsleep;
    asleep_.store(true, std::memory_order_relaxed);
    sleeps_.fetch_add(1, std::memory_order_relaxed);
  }
}

void HapticLoop::WakeSecondaries(std::int64_t origin_ns) noexcept {
  wake_origin_ns_.store(origin_ns, std::memory_order_relaxed);
  for (auto& parked : parked_) parked.store(false, std::memory_order_relaxed);
  park_secondaries_.store(false, std::memory_order_relaxed);
  wake_generation_.fetch_add(1, std::memory_order_release);  // publishes the stores above
  FutexWakeAll(&wake_generation_);
  sleep_state_ = kAwake;
  asleep_.store(false, std::memory_order_relaxed);
}

}  // namespace hapticsim
