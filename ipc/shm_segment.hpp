#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "ipc/shm_layout.hpp"

namespace hapticsim::shm {

/** The bytes of a segment whose deformed surface has `deformation_nodes` nodes. */
std::size_t SegmentBytes(std::uint32_t deformation_nodes);

/**
 * Writes a fresh segment, header, empty rings and an empty deformation area, into `memory`
 * (SegmentBytes bytes) as the daemon `daemon_pid` makes it; the magic last, so a reader sees it
 * only when the rest is there.
 */
ShmSegment* FormatSegment(void* memory, std::int64_t daemon_pid,
                          std::uint32_t deformation_nodes = 0);

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
  static MappedSegment CreateSealed(const std::string& label, std::uint32_t deformation_nodes = 0);
  /**
   * A driver: maps the segment behind `fd` (taking it: it is closed, whatever happens) after
   * checking that it is sealed against size changes, its header (magic, layout version, slot
   * sizes) and that its size is what the header says (the rings and the deformation area). `from`
   * names where it came from, for messages.
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
  /**
   * The deformed surface's two frames in this segment, where they were when it was made or
   * adopted: the other side can write the header, so its offset and size are never read again.
   */
  ShmDeformationArea deformation() const {
    return ShmDeformationArea(reinterpret_cast<std::atomic<std::uint64_t>*>(
                                  reinterpret_cast<char*>(segment_) + sizeof(ShmSegment)),
                              deformation_nodes_);
  }

 private:
  MappedSegment(ShmSegment* segment, std::size_t bytes, std::uint32_t deformation_nodes, int fd,
                bool owner)
      : segment_(segment),
        bytes_(bytes),
        deformation_nodes_(deformation_nodes),
        fd_(fd),
        owner_(owner) {}
  ShmSegment* segment_ = nullptr;
  std::size_t bytes_ = 0;
  std::uint32_t deformation_nodes_ = 0;
  int fd_ = -1;
  bool owner_ = false;
};

}  // namespace hapticsim::shm
