#include "ipc/shm_segment.hpp"

#include <fcntl.h>
#include <linux/falloc.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <new>

#include "core/error.hpp"

namespace hapticsim::shm {
namespace {

std::string Why() { return std::strerror(errno); }

/** The seals a segment must carry: its size is fixed for good. */
constexpr int kRequiredSeals = F_SEAL_SHRINK | F_SEAL_GROW | F_SEAL_SEAL;

/**
 * The most surface nodes a segment is made for: a 130³ lattice's surface, 6.4 MB a frame (the
 * I/O thread writes each frame; the default 13³ cube's 866 nodes are 28 KB).
 */
constexpr std::uint32_t kMaxDeformationNodes = 100'000;

}  // namespace

std::size_t SegmentBytes(std::uint32_t deformation_nodes) {
  return sizeof(ShmSegment) + ShmDeformationArea::Bytes(deformation_nodes);
}

ShmSegment* FormatSegment(void* memory, std::int64_t daemon_pid, std::uint32_t deformation_nodes) {
  auto* segment = new (memory) ShmSegment();
  ShmHeader& h = segment->header;
  h.layout_version = kLayoutVersion;
  h.header_bytes = sizeof(ShmHeader);
  h.input_slot_bytes = sizeof(SeqlockSlot<ShmDeviceInput>);
  h.output_slot_bytes = sizeof(SeqlockSlot<ShmForceOutput>);
  h.total_bytes = SegmentBytes(deformation_nodes);
  h.deformation_offset = sizeof(ShmSegment);
  h.deformation_nodes = deformation_nodes;
  h.reserved = 0;
  ShmDeformationArea(reinterpret_cast<std::atomic<std::uint64_t>*>(static_cast<char*>(memory) +
                                                                   sizeof(ShmSegment)),
                     deformation_nodes)
      .Clear();
  h.daemon_pid.store(daemon_pid);
  std::atomic_thread_fence(std::memory_order_release);
  std::memcpy(h.magic, kMagic, sizeof kMagic);  // last: a reader sees the magic only when ready
  return segment;
}

MappedSegment MappedSegment::CreateSealed(const std::string& label,
                                          std::uint32_t deformation_nodes) {
  HAPTICSIM_THROW_UNLESS(deformation_nodes <= kMaxDeformationNodes,
                         "cannot make a shared segment for " + std::to_string(deformation_nodes) +
                             " surface nodes: at most " + std::to_string(kMaxDeformationNodes));
  const std::size_t bytes = SegmentBytes(deformation_nodes);
  const int fd = memfd_create(label.c_str(), MFD_CLOEXEC | MFD_ALLOW_SEALING);
  HAPTICSIM_THROW_UNLESS(fd >= 0, "cannot create the shared segment: memfd_create: " + Why());
  auto fail = [&](const std::string& what) {
    const std::string why = Why();
    close(fd);
    throw Error("cannot " + what + " the shared segment: " + why);
  };
  if (ftruncate(fd, static_cast<off_t>(bytes)) != 0) fail("size");
  // Sealed before any other process holds it: nobody, the daemon included, can change its size.
  if (fcntl(fd, F_ADD_SEALS, kRequiredSeals) != 0) fail("seal");
  void* memory = mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
  if (memory == MAP_FAILED) fail("map");
  ShmSegment* segment = FormatSegment(memory, getpid(), deformation_nodes);
  return MappedSegment(segment, bytes, deformation_nodes, fd, true);
}

MappedSegment MappedSegment::Adopt(int fd, const std::string& from) {
  auto refuse = [&](const std::string& problem) {
    close(fd);
    throw Error("the shared segment from " + from + " " + problem);
  };
  // Unsealed, the sender (or anyone it shared the file with) could shrink it under this mapping:
  // the next access would kill this process with SIGBUS.
  const int seals = fcntl(fd, F_GET_SEALS);
  if (seals < 0) refuse("is not a sealable memory file (" + Why() + "): not hapticsimd's");
  if ((seals & kRequiredSeals) != kRequiredSeals) {
    refuse("is not sealed against size changes (seals " + std::to_string(seals) +
           "): not hapticsimd's");
  }
  struct stat info {};
  if (fstat(fd, &info) != 0) refuse("cannot be examined: " + Why());
  const auto bytes = static_cast<std::size_t>(info.st_size);
  if (info.st_size < 0 || bytes < sizeof(ShmSegment) ||
      bytes > SegmentBytes(kMaxDeformationNodes)) {
    refuse("has " + std::to_string(info.st_size) + " bytes; this client expects from " +
           std::to_string(sizeof(ShmSegment)) + " (another layout version?)");
  }
  void* memory = mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
  if (memory == MAP_FAILED) refuse("cannot be mapped: " + Why());
  close(fd);
  auto* segment = static_cast<ShmSegment*>(memory);
  const ShmHeader& h = segment->header;
  // Read once: the other side can write the header meanwhile (what is checked is what is used).
  const std::uint32_t deformation_nodes =
      std::atomic_ref<std::uint32_t>(segment->header.deformation_nodes)
          .load(std::memory_order_relaxed);
  std::string problem;
  if (std::memcmp(h.magic, kMagic, sizeof kMagic) != 0) {
    problem = "has no hapticsim signature (not hapticsimd's)";
  } else if (h.layout_version != kLayoutVersion) {
    problem = "has layout version " + std::to_string(h.layout_version) + "; this client speaks " +
              std::to_string(kLayoutVersion);
  } else if (h.header_bytes != sizeof(ShmHeader) ||
             h.input_slot_bytes != sizeof(SeqlockSlot<ShmDeviceInput>) ||
             h.output_slot_bytes != sizeof(SeqlockSlot<ShmForceOutput>) ||
             h.deformation_offset != sizeof(ShmSegment) ||
             deformation_nodes > kMaxDeformationNodes || SegmentBytes(deformation_nodes) != bytes ||
             h.total_bytes != bytes) {
    problem = "has other slot sizes than this client (built from another version?)";
  }
  if (!problem.empty()) {
    munmap(memory, bytes);
    throw Error("the shared segment from " + from + " " + problem);
  }
  return MappedSegment(segment, bytes, deformation_nodes, -1, false);
}

MappedSegment::MappedSegment(MappedSegment&& other) noexcept
    : segment_(other.segment_),
      bytes_(other.bytes_),
      deformation_nodes_(other.deformation_nodes_),
      fd_(other.fd_),
      owner_(other.owner_) {
  other.segment_ = nullptr;
  other.fd_ = -1;
}

MappedSegment::~MappedSegment() {
  if (!segment_) return;
  if (owner_) segment_->header.daemon_pid.store(0);
  munmap(segment_, bytes_);
  if (fd_ >= 0) {
    // The driver may keep its descriptor for ever: the pages go back now, or a driver that
    // starts session after session and keeps each would pile them up in the daemon's memory.
    // What it reads after this is zeros: no signature, daemon_pid 0, "no force source".
    fallocate(fd_, FALLOC_FL_PUNCH_HOLE | FALLOC_FL_KEEP_SIZE, 0, static_cast<off_t>(bytes_));
    close(fd_);
  }
}

}  // namespace hapticsim::shm
