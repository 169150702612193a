#pragma once

// The shared-memory interface between a device driver and hapticsimd: the layout both sides map.
// For driver writers: use ShmDeviceClient (shm_device_client.hpp) rather than this file directly.
//
// One anonymous memory file per driver session, created and sealed by the daemon and handed to the
// driver over the service socket (ipc/service_socket.hpp, ipc/shm_segment.hpp). Layout:
//
//   ShmHeader | newest_input, kInputSlots × SeqlockSlot<ShmDeviceInput> (the driver writes)
//             | newest_output, kOutputSlots × SeqlockSlot<ShmForceOutput> (the daemon writes)
//             | the deformed surface: two seqlocked frames (ShmDeformationArea, the daemon writes)
//
// Both directions are rings with a single writer: write number w goes to slot w % slots, then w
// is published as the newest. Each slot is a seqlock over relaxed atomic words (lock-free and
// address-free, so it works across processes). A reader that races a writer retries; a writer
// that dies mid-write leaves an odd sequence and does not publish that write, which readers see
// as "nothing new" — the daemon then treats the input as stale. The input ring lets a driver
// that was held up write two inputs within one of the daemon's polls without losing the first
// (every input gets its answer); the output ring does the same for the driver.

#include <atomic>
#include <bit>
#include <climits>
#include <cstddef>
#include <cstdint>

#include "rt/seqlock_slot.hpp"

namespace hapticsim::shm {

inline constexpr char kMagic[8] = {'H', 'S', 'I', 'M', 'S', 'H', 'M', '1'};
inline constexpr std::uint32_t kLayoutVersion = 4;

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
  /// The deformed surface's area (ShmDeformationArea): bytes from the segment's start (right
  /// after ShmSegment), and the surface nodes each of its frames holds. total_bytes covers it.
  std::uint64_t deformation_offset;
  std::uint32_t deformation_nodes;
  std::uint32_t reserved;
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

/** One frame of the deformed surface as a reader gets it (ShmDeformationArea::Read). */
struct ShmDeformationFrame {
  std::int64_t frame = -1;             ///< frames the daemon made since it started
  std::int64_t utime = 0;              ///< when it was made, µs (the daemon's CLOCK_MONOTONIC)
  std::int64_t configuration_id = -1;  ///< changes whenever the regions are replaced
  bool in_contact = false;             ///< the tool engaged within the last 5 primary periods
  bool complete = true;                ///< every region published its part after being asked
  std::int32_t nodes_per_axis = 0;     ///< n, the largest count: id = (ix · n + iy) · n + iz
  double spacing_m = 0;                ///< lattice spacing, m: rest position = index · spacing
  std::int32_t contact_node[3] = {};   ///< the node the regions are centred on
  std::uint32_t num_nodes = 0;         ///< surface nodes in the frame (ShmDeformationArea::nodes)
};

/**
 * The deformed surface in the segment (docs/simulator.md, "The deformed shape"): two frames, each
 * behind a seqlock, written in turn by the daemon's I/O thread at [deformation] rate_hz; the
 * newest written is published, so a reader copies a whole frame while the next is written into
 * the other. All words are relaxed atomics (address-free across processes). Per frame, in 8-byte
 * words: sequence, frame, utime, configuration_id, flags (1 in contact, 2 complete),
 * nodes_per_axis, spacing_m, contact node (ix | iy << 16 | iz << 32), then `nodes` ids and
 * 3 × `nodes` displacements (x, y, z per node, m, as doubles).
 */
class ShmDeformationArea {
 public:
  static constexpr std::size_t kMetaWords = 8;
  static constexpr std::size_t kNewestWords = 8;  // the newest frame's index, on a line of its own
  static std::size_t FrameWords(std::uint32_t nodes) { return kMetaWords + 4 * std::size_t{nodes}; }
  static std::size_t Bytes(std::uint32_t nodes) {
    return 8 * (kNewestWords + 2 * FrameWords(nodes));
  }

  ShmDeformationArea(std::atomic<std::uint64_t>* words, std::uint32_t nodes)
      : words_(words), nodes_(nodes) {}
  std::uint32_t nodes() const { return nodes_; }

  /** Marks the area empty (the daemon, formatting a segment). */
  void Clear() {
    for (std::size_t i = 0; i < Bytes(nodes_) / 8; ++i)
      words_[i].store(0, std::memory_order_relaxed);
    words_[0].store(static_cast<std::uint64_t>(-1), std::memory_order_release);
  }

  /**
   * The daemon's I/O thread, the single writer: write number `write` (0, 1, 2, … counted by the
   * writer itself, never read back from the segment, which the driver can write too) into frame
   * `write` & 1, then publishes it. `ids` and `displacement_m` hold nodes() and 3 × nodes() values.
   */
  void Write(std::int64_t write, const ShmDeformationFrame& meta, const std::int32_t* ids,
             const double* displacement_m) {
    std::atomic<std::uint64_t>* f = Frame(write);
    // The driver may have written the sequence word: odd or not, the next store makes it odd.
    const std::uint64_t seq = f[0].load(std::memory_order_relaxed) & ~std::uint64_t{1};
    f[0].store(seq + 1, std::memory_order_relaxed);  // odd: writing
    std::atomic_thread_fence(std::memory_order_release);
    auto put = [&](std::size_t i, std::uint64_t v) { f[i].store(v, std::memory_order_relaxed); };
    put(1, static_cast<std::uint64_t>(meta.frame));
    put(2, static_cast<std::uint64_t>(meta.utime));
    put(3, static_cast<std::uint64_t>(meta.configuration_id));
    put(4, (meta.in_contact ? 1u : 0u) | (meta.complete ? 2u : 0u));
    put(5, static_cast<std::uint64_t>(meta.nodes_per_axis));
    put(6, std::bit_cast<std::uint64_t>(meta.spacing_m));
    put(7, static_cast<std::uint64_t>(static_cast<std::uint16_t>(meta.contact_node[0])) |
               static_cast<std::uint64_t>(static_cast<std::uint16_t>(meta.contact_node[1])) << 16 |
               static_cast<std::uint64_t>(static_cast<std::uint16_t>(meta.contact_node[2])) << 32);
    for (std::size_t i = 0; i < nodes_; ++i) {
      put(kMetaWords + i, static_cast<std::uint64_t>(static_cast<std::uint32_t>(ids[i])));
    }
    for (std::size_t i = 0; i < 3 * std::size_t{nodes_}; ++i) {
      put(kMetaWords + nodes_ + i, std::bit_cast<std::uint64_t>(displacement_m[i]));
    }
    f[0].store(seq + 2, std::memory_order_release);  // even: whole
    words_[0].store(static_cast<std::uint64_t>(write), std::memory_order_release);
  }

  /**
   * Any reader: the newest whole frame. `ids` (nodes() of them) and `displacement_m` (3 ×
   * nodes()) may each be null to skip them. False when no frame was written yet, or writes raced
   * every attempt (the writer lapped this reader 16 times): the arrays may then hold parts of
   * several frames. Wait-free: no lock, no allocation.
   */
  bool Read(ShmDeformationFrame* meta, std::int32_t* ids, double* displacement_m) const {
    for (int attempt = 0; attempt < 16; ++attempt) {
      const auto newest = static_cast<std::int64_t>(words_[0].load(std::memory_order_acquire));
      if (newest < 0) return false;
      const std::atomic<std::uint64_t>* f = Frame(newest);
      const std::uint64_t before = f[0].load(std::memory_order_acquire);
      if (before == 0 || (before & 1)) continue;
      auto get = [&](std::size_t i) { return f[i].load(std::memory_order_relaxed); };
      ShmDeformationFrame m;
      m.frame = static_cast<std::int64_t>(get(1));
      m.utime = static_cast<std::int64_t>(get(2));
      m.configuration_id = static_cast<std::int64_t>(get(3));
      m.in_contact = get(4) & 1;
      m.complete = get(4) & 2;
      m.nodes_per_axis = static_cast<std::int32_t>(get(5));
      m.num_nodes = nodes_;
      m.spacing_m = std::bit_cast<double>(get(6));
      for (int c = 0; c < 3; ++c) {
        m.contact_node[c] = static_cast<std::int32_t>((get(7) >> (16 * c)) & 0xffff);
      }
      if (ids) {
        for (std::size_t i = 0; i < nodes_; ++i) {
          ids[i] = static_cast<std::int32_t>(get(kMetaWords + i));
        }
      }
      if (displacement_m) {
        for (std::size_t i = 0; i < 3 * std::size_t{nodes_}; ++i) {
          displacement_m[i] = std::bit_cast<double>(get(kMetaWords + nodes_ + i));
        }
      }
      std::atomic_thread_fence(std::memory_order_acquire);
      if (f[0].load(std::memory_order_relaxed) != before) continue;
      *meta = m;
      return true;
    }
    return false;
  }

 private:
  std::atomic<std::uint64_t>* Frame(std::int64_t number) const {
    return words_ + kNewestWords + static_cast<std::size_t>(number & 1) * FrameWords(nodes_);
  }
  std::atomic<std::uint64_t>* words_;
  std::uint32_t nodes_;
};

static_assert(std::atomic<std::uint64_t>::is_always_lock_free &&
                  std::atomic<std::int64_t>::is_always_lock_free,
              "the shared slots need lock-free 64-bit atomics");

}  // namespace hapticsim::shm
