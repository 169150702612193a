#pragma once

// The shared-memory interface between a device driver and hapticsimd: the layout both sides map.
// For driver writers: use ShmDeviceClient (shm_device_client.hpp) rather than this file directly.
//
// One POSIX shared-memory object (default name "/hapticsim", in /dev/shm), created by the daemon
// with mode 0660 (owner and the configured group; other users get nothing). Layout:
//
//   ShmHeader | SeqlockSlot<ShmDeviceInput> (driver writes) | SeqlockSlot<ShmForceOutput> (daemon)
//
// Each slot has a single writer and holds the newest value: a seqlock over relaxed atomic words
// (lock-free and address-free, so it works across processes). A reader that races a writer
// retries; a writer that dies mid-write leaves an odd sequence, which readers see as "no
// consistent value" — the daemon then treats the input as stale.

#include <atomic>
#include <cstdint>

#include "core/seqlock_slot.hpp"

namespace hapticsim::shm {

inline constexpr char kMagic[8] = {'H', 'S', 'I', 'M', 'S', 'H', 'M', '1'};
inline constexpr std::uint32_t kLayoutVersion = 2;
inline constexpr const char* kDefaultName = "/hapticsim";

/** The tool tip, written by the driver every device period. Object frame, as in LCM. */
struct ShmDeviceInput {
  std::int64_t seq = 0;       ///< increases by one per write; answered in ShmForceOutput::seq
  std::int64_t utime = 0;     ///< driver's clock, µs
  double position_m[3] = {};  ///< tool-tip position, m
};

/** The force, written by the daemon every primary period. */
struct ShmForceOutput {
  std::int64_t period = -1;   ///< the daemon's primary period, counting every one from 0
  std::int64_t seq = -1;      ///< the input it answers (-1: none yet)
  std::int64_t utime = 0;     ///< daemon's CLOCK_MONOTONIC, µs
  double force_n[3] = {};     ///< force on the user, N
  double error_percent = -1;  ///< looked-up error, % (-1: no map)
  std::int32_t flags = 0;     ///< force_feedback_t::FLAG_* bits
};

/** Answers the ring keeps: 64 ms at 1 kHz. */
inline constexpr int kOutputSlots = 64;

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
  alignas(64) SeqlockSlot<ShmDeviceInput> input;
  // The answers, in a ring: period p's answer goes to outputs[p % kOutputSlots], then p is
  // published as newest_output. A driver descheduled for a few periods reads what it missed
  // (up to kOutputSlots periods back) instead of losing it.
  alignas(64) std::atomic<std::int64_t> newest_output{-1};
  alignas(64) SeqlockSlot<ShmForceOutput> outputs[kOutputSlots];
};

static_assert(std::atomic<std::uint64_t>::is_always_lock_free &&
                  std::atomic<std::int64_t>::is_always_lock_free,
              "the shared slots need lock-free 64-bit atomics");

}  // namespace hapticsim::shm
