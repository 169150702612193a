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

}  // namespace

ShmSegment* FormatSegment(void* memory, std::int64_t daemon_pid) {
  auto* segment = new (memory) ShmSegment();
  ShmHeader& h = segment->header;
  h.layout_version = kLayoutVersion;
  h.header_bytes = sizeof(ShmHeader);
  h.input_slot_bytes = sizeof(SeqlockSlot<ShmDeviceInput>);
  h.output_slot_bytes = sizeof(SeqlockSlot<ShmForceOutput>);
  h.total_bytes = sizeof(ShmSegment);
  h.daemon_pid.store(daemon_pid);
  std::atomic_thread_fence(std::memory_order_release);
  std::memcpy(h.magic, kMagic, sizeof kMagic);  // last: a reader sees the magic only when ready
  return segment;
}

MappedSegment MappedSegment::CreateSealed(const std::string& label) {
  const int fd = memfd_create(label.c_str(), MFD_CLOEXEC | MFD_ALLOW_SEALING);
  HAPTICSIM_THROW_UNLESS(fd >= 0, "cannot create the shared segment: memfd_create: " + Why());
  auto fail = [&](const std::string& what) {
    const std::string why = Why();
    close(fd);
    throw Error("cannot " + what + " the shared segment: " + why);
  };
  if (ftruncate(fd, sizeof(ShmSegment)) != 0) fail("size");
  // Sealed before any other process holds it: nobody, the daemon included, can change its size.
  if (fcntl(fd, F_ADD_SEALS, kRequiredSeals) != 0) fail("seal");
  void* memory = mmap(nullptr, sizeof(ShmSegment), PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
  if (memory == MAP_FAILED) fail("map");
  ShmSegment* segment = FormatSegment(memory, getpid());
  return MappedSegment(segment, fd, true);
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
  if (static_cast<size_t>(info.st_size) != sizeof(ShmSegment)) {
    refuse("has " + std::to_string(info.st_size) + " bytes; this client expects " +
           std::to_string(sizeof(ShmSegment)) + " (another layout version?)");
  }
  void* memory = mmap(nullptr, sizeof(ShmSegment), PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
  if (memory == MAP_FAILED) refuse("cannot be mapped: " + Why());
  close(fd);
  auto* segment = static_cast<ShmSegment*>(memory);
  const ShmHeader& h = segment->header;
  std::string problem;
  if (std::memcmp(h.magic, kMagic, sizeof kMagic) != 0) {
    problem = "has no hapticsim signature (not hapticsimd's)";
  } else if (h.layout_version != kLayoutVersion) {
    problem = "has layout version " + std::to_string(h.layout_version) + "; this client speaks " +
              std::to_string(kLayoutVersion);
  } else if (h.header_bytes != sizeof(ShmHeader) ||
             h.input_slot_bytes != sizeof(SeqlockSlot<ShmDeviceInput>) ||
             h.output_slot_bytes != sizeof(SeqlockSlot<ShmForceOutput>) ||
             h.total_bytes != sizeof(ShmSegment)) {
    problem = "has other slot sizes than this client (built from another version?)";
  }
  if (!problem.empty()) {
    munmap(memory, sizeof(ShmSegment));
    throw Error("the shared segment from " + from + " " + problem);
  }
  return MappedSegment(segment, -1, false);
}

MappedSegment::MappedSegment(MappedSegment&& other) noexcept
    : segment_(other.segment_), fd_(other.fd_), owner_(other.owner_) {
  other.segment_ = nullptr;
  other.fd_ = -1;
}

MappedSegment::~MappedSegment() {
  if (!segment_) return;
  if (owner_) segment_->header.daemon_pid.store(0);
  munmap(segment_, sizeof(ShmSegment));
  if (fd_ >= 0) {
    // The driver may keep its descriptor for ever: the pages go back now, or a driver that
    // starts session after session and keeps each would pile them up in the daemon's memory.
    // What it reads after this is zeros: no signature, daemon_pid 0, "no force source".
    fallocate(fd_, FALLOC_FL_PUNCH_HOLE | FALLOC_FL_KEEP_SIZE, 0, sizeof(ShmSegment));
    close(fd_);
  }
}

}  // namespace hapticsim::shm
