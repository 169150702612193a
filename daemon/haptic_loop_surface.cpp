// The deformed surface out of hapticsimd's running loop (HapticLoop::TakeSurface), for the
// deformation thread: the regions publish their parts when asked, after their own next step
// (AsyncRegions::RequestSurface), so the real-time threads do no more than copy them.
#include <chrono>
#include <mutex>
#include <thread>

#include "daemon/haptic_loop.hpp"

namespace hapticsim {

bool HapticLoop::TakeSurface(std::int64_t max_wait_ns, SurfaceFrame* frame) {
  // How often the thread looks whether every region has published: the primary does within a
  // millisecond, the slowest shell within its own period.
  constexpr auto kPoll = std::chrono::microseconds(500);
  std::int64_t install = 0;
  std::uint64_t request = 0;
  frame->asked_ns = NowNs();
  {
    const std::lock_guard<std::mutex> lock(surface_mutex_);
    install = installs_;
    request = regions_->RequestSurface();
  }
  for (;;) {
    {
      const std::lock_guard<std::mutex> lock(surface_mutex_);
      if (installs_ != install) return false;
      const bool served = regions_->SurfaceServed(request);
      // Asleep, the regions were set exactly to rest and published that; they step no more.
      const bool waited_enough = asleep() || NowNs() - frame->asked_ns >= max_wait_ns;
      if (served || waited_enough) {
        if (!regions_->ReadSurface(&frame->displacement_m)) return false;
        frame->complete = served;
        if (frame->configuration_id != installs_) {
          object_.ToWireIds(regions_->surface_ids(), &frame->ids);
          frame->nodes_per_axis = object_.wire_nodes_per_axis();
          frame->spacing_m = object_.spacing_m();
        }
        frame->configuration_id = installs_;
        frame->configuration = scene_.adaptivity;
        frame->centre = regions_->partition().contact_node();
        break;
      }
    }
    std::this_thread::sleep_for(kPoll);
  }
  // In contact as the newest period answered, whenever that was: a primary woken late beside a
  // busy neighbour has not let go. The five periods bridge a reconfiguration's pause that was not
  // held, where one period answers out of contact.
  const double primary_period_ns = primary_period_ns_;
  frame->in_contact =
      counters_.in_contact.value() ||
      NowNs() - last_contact_ns() <= static_cast<std::int64_t>(5 * primary_period_ns);
  return true;
}

}  // namespace hapticsim
