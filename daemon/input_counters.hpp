#pragma once

#include <array>
#include <atomic>
#include <cstdint>

#include "daemon/input_guard.hpp"

namespace hapticsim {

/** What came in and went out, over LCM and shared memory together (the status message's counts). */
struct InputCounters {
  std::atomic<std::int64_t> inputs_received{0}, inputs_rejected{0}, decode_errors{0};
  std::atomic<std::int64_t> forces_published{0}, commands_received{0};
  /// Device inputs on the transport that does not own the input (device.input): refused unread.
  std::atomic<std::int64_t> inputs_wrong_transport{0};
  /// Driver sessions started on the service socket, and connections refused there.
  std::atomic<std::int64_t> shm_sessions{0}, shm_refused{0};
  /// Commands refused, over LCM and hapticsim ctl (status_t::commands_refused says which ones).
  std::atomic<std::int64_t> commands_refused{0};
  std::array<std::atomic<std::int64_t>, kNumInputRejections> rejected_by_kind{};
  std::atomic<int> last_rejection{0};  ///< newest rejection not yet logged (InputRejection)

  void Reject(InputRejection why) {
    inputs_rejected.fetch_add(1);
    rejected_by_kind[static_cast<int>(why)].fetch_add(1);
    last_rejection.store(static_cast<int>(why));
  }
};

}  // namespace hapticsim
