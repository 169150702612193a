#pragma once

// The shared-memory interface between a device driver and hapticsimd: the layout both sides map.
// For driver writers: use ShmDeviceClient (shm_device_client.hpp) rather than this file directly.
//
// One anonymous memory file per driver session, created and sealed by the daemon and handed to the
// driver over the service socket (ipc/service_socket.hpp, ipc/shm_segment.hpp). Layout:
//
//   ShmHeader | newest_input, kInputSlots × SeqlockSlot<ShmDeviceInput> (the driver writes)
//             | newest_output, kOutputSlots × SeqlockSlot<ShmForceOutput> (the daemon writes)
//
// Both directions are rings with a single writer: write number w goes to slot w % slots, then w
// is published as the newest. Each slot is a seqlock over relaxed atomic words (lock-free and
// address-free, so it works across processes). A reader that races a writer retries; a writer
// that dies mid-write leaves an odd sequence and does not publish that write, which readers see
// as "nothing new" — the daemon then treats the input as stale. The input ring lets a driver
// that was held up write two inputs within one of the daemon's polls without losing the first
// (every input gets its answer); the output ring does the same for the driver.

#include <atomic>
#include <climits>
#include <cstdint>

#include "core/seqlock_slot.hpp"

namespace hapticsim::shm {

inline constexpr char kMagic[8] = {'H', 'S', 'I', 'M', 'S', 'H', 'M', '1'};
inline constexpr std::uint32_t kLayoutVersion = 3;

/** The tool tip, written by the driver every device period. Object frame, as in LCM. */
struct ShmDeviceInput {
  std::int64_t seq = 0;       ///< increases by one per write; answered in ShmForceOutput::seq
  std::int64_t utime = 0;     ///< driver's clock, µs
  double position_m[3] = {};  ///< tool-tip position, m
};

/** The force, written by the daemon every primary period. */
struct ShmForceOutput {
  std::int64_t period = -1;     ///< the daemon's primary period, counting every one from 0
  std::int64_t seq = -1;        ///< the newest input it answers (-1: none yet)
  std::int64_t first_seq = -1;  ///< the oldest it answers: all from first_seq to seq were used
  std::int64_t utime = 0;       ///< daemon's CLOCK_MONOTONIC, µs
  double force_n[3] = {};       ///< force on the user, N
  double error_percent = -1;    ///< looked-up error, % (-1: no map)
  std::int32_t flags = 0;       ///< force_feedback_t::FLAG_* bits
};

/**
 * Answers the ring keeps: 256 ms at 1 kHz. A desktop with two busy threads stalls a normal-priority
 * process for up to 100 ms now and then (measured, docs/reliability.md); 64 lost answers then.
 */
inline constexpr int kOutputSlots = 256;
/** Inputs the ring keeps until the daemon reads them: 256 ms at 1 kHz, for the same stalls. */
inline constexpr int kInputSlots = 256;

struct ShmHeader {
  char magic[8];
  std::uint32_t layout_version;
  std::uint32_t header_bytes;
  std::uint32_t input_slot_bytes;
  std::uint32_t output_slot_bytes;
  std::uint64_t total_bytes;
  std::atomic<std::int64_t> daemon_pid;           ///< 0 once the daemon has stopped
  std::atomic<std::int64_t> daemon_heartbeat_ns;  ///< CLOCK_MONOTONIC of its last output
};

struct ShmSegment {
  ShmHeader header;
  // The driver's inputs, in a ring: its write number w goes to inputs[w % kInputSlots], then w is
  // published as newest_input (ShmDeviceClient::WriteInput; the daemon reads with
  // ShmInputReader).
  alignas(64) std::atomic<std::int64_t> newest_input{-1};
  alignas(64) SeqlockSlot<ShmDeviceInput> inputs[kInputSlots];
  // The answers, in a ring: period p's answer goes to outputs[p % kOutputSlots], then p is
  // published as newest_output. A driver descheduled for a few periods reads what it missed
  // (up to kOutputSlots periods back) instead of losing it.
  alignas(64) std::atomic<std::int64_t> newest_output{-1};
  alignas(64) SeqlockSlot<ShmForceOutput> outputs[kOutputSlots];
};

/**
 * The driver's side of the input ring: writes the next input and publishes it. A restarted writer
 * goes on from the ring's newest write (from 0 if that is nonsense). Wait-free.
 */
inline void WriteDeviceInput(ShmSegment& segment, const ShmDeviceInput& input) {
  const std::int64_t newest = segment.newest_input.load(std::memory_order_relaxed);
  const std::int64_t next = newest >= 0 && newest < INT64_MAX ? newest + 1 : 0;
  segment.inputs[static_cast<std::uint64_t>(next) % kInputSlots].Write(input);
  segment.newest_input.store(next, std::memory_order_release);
}

/**
 * The daemon's side of the input ring: each call hands every input written since the last one to
 * `each`, oldest first. At most kInputSlots − 1: older ones were overwritten, and the slot after
 * the newest may be being written (a reader that far behind must not read it). Whatever a broken
 * or hostile writer sets the index to (negative, huge, going back), it reads inside the ring and
 * at most that many slots, and then follows the writer's newest write.
 */
class ShmInputReader {
 public:
  template <typename Each>
  int ReadNew(const ShmSegment& segment, Each each) {
    const std::int64_t newest = segment.newest_input.load(std::memory_order_acquire);
    if (newest < 0) {  // nothing written yet (or nonsense): start from the next write
      last_ = -1;
      return 0;
    }
    if (newest <= last_) {
      if (newest < last_) last_ = newest - 1;  // went back: a writer that started over
      if (newest == last_) return 0;
    }
    // How many writes since the last read, in unsigned arithmetic (no overflow), at most the
    // ring less the slot that may be being written.
    const std::uint64_t behind =
        static_cast<std::uint64_t>(newest) - static_cast<std::uint64_t>(last_ < 0 ? -1 : last_);
    const std::uint64_t count = behind < kInputSlots - 1 ? behind : kInputSlots - 1;
    int read = 0;
    for (std::uint64_t k = count; k > 0; --k) {
      const std::uint64_t write = static_cast<std::uint64_t>(newest) - (k - 1);
      ShmDeviceInput input;
      if (segment.inputs[write % kInputSlots].Read(&input)) each(input), ++read;
    }
    last_ = newest;
    return read;
  }

 private:
  std::int64_t last_ = -1;
};

static_assert(std::atomic<std::uint64_t>::is_always_lock_free &&
                  std::atomic<std::int64_t>::is_always_lock_free,
              "the shared slots need lock-free 64-bit atomics");

}  // namespace hapticsim::shm
