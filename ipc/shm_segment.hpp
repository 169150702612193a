#pragma once

#include <cstdint>
#include <string>

#include "ipc/shm_layout.hpp"

namespace hapticsim::shm {

/**
 * Writes a fresh segment, header and empty rings, into `memory` (sizeof(ShmSegment) bytes) as the
 * daemon `daemon_pid` makes it; the magic last, so a reader sees it only when the rest is there.
 */
ShmSegment* FormatSegment(void* memory, std::int64_t daemon_pid);

/**
 * A mapping of the segment. The daemon creates it (CreateSealed) and hands its file descriptor to
 * one driver over the service socket (ipc/service_socket.hpp); the driver maps what it received
 * (Adopt). Both unmap on destruction.
 *
 * The segment is an anonymous memory file (memfd), sealed against shrinking and growing before
 * anyone else sees it: no client can truncate it under the daemon (a SIGBUS in the daemon's next
 * access), grow it, or remove the seals. It has no name, so no other process can open it, squat
 * on it, or replace it: only the driver the daemon handed it to can map it.
 */
class MappedSegment {
 public:
  /**
   * The daemon: a new sealed segment, its header written, mapped. `label` names it in
   * /proc/PID/fd (memfd:label). @throws Error saying what failed.
   */
  static MappedSegment CreateSealed(const std::string& label);
  /**
   * A driver: maps the segment behind `fd` (taking it: it is closed, whatever happens) after
   * checking that it is sealed against size changes, that its size is this layout's, and its
   * header (magic, layout version, slot sizes). `from` names where it came from, for messages.
   * @throws Error saying which check failed.
   */
  static MappedSegment Adopt(int fd, const std::string& from);

  MappedSegment(MappedSegment&& other) noexcept;
  MappedSegment& operator=(MappedSegment&&) = delete;
  ~MappedSegment();

  ShmSegment& segment() { return *segment_; }
  const ShmSegment& segment() const { return *segment_; }
  /** The creator's descriptor of the memory file, to hand to a driver; -1 in a driver. */
  int fd() const { return fd_; }

 private:
  MappedSegment(ShmSegment* segment, int fd, bool owner)
      : segment_(segment), fd_(fd), owner_(owner) {}
  ShmSegment* segment_ = nullptr;
  int fd_ = -1;
  bool owner_ = false;
};

}  // namespace hapticsim::shm
