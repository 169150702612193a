#include "ipc/shm_segment.hpp"

#include <fcntl.h>
#include <grp.h>
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

}  // namespace

MappedSegment MappedSegment::Create(const std::string& name, const std::string& group) {
  HAPTICSIM_THROW_UNLESS(
      name.size() > 1 && name[0] == '/' && name.find('/', 1) == std::string::npos,
      "shm.name = \"" + name + "\": must be one '/' then a name, e.g. /hapticsim");
  shm_unlink(name.c_str());  // a segment left by a crashed daemon
  const int fd = shm_open(name.c_str(), O_RDWR | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
  HAPTICSIM_THROW_UNLESS(fd >= 0, "cannot create shared memory " + name + ": " + Why());
  auto fail = [&](const std::string& message) {
    close(fd);
    shm_unlink(name.c_str());
    throw Error(message);
  };
  if (!group.empty()) {
    const struct group* entry = getgrnam(group.c_str());
    if (!entry) fail("shm.group = \"" + group + "\": no such group");
    if (fchown(fd, static_cast<uid_t>(-1), entry->gr_gid) != 0) {
      fail("cannot give " + name + " to group " + group + ": " + Why());
    }
  }
  // 0660 whatever the umask: the owner and the group (the driver's), nobody else.
  if (fchmod(fd, 0660) != 0) fail("cannot set the mode of " + name + ": " + Why());
  if (ftruncate(fd, sizeof(ShmSegment)) != 0) fail("cannot size " + name + ": " + Why());
  void* memory = mmap(nullptr, sizeof(ShmSegment), PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
  close(fd);
  if (memory == MAP_FAILED) {
    shm_unlink(name.c_str());
    throw Error("cannot map " + name + ": " + Why());
  }
  auto* segment = new (memory) ShmSegment();
  ShmHeader& h = segment->header;
  h.layout_version = kLayoutVersion;
  h.header_bytes = sizeof(ShmHeader);
  h.input_slot_bytes = sizeof(SeqlockSlot<ShmDeviceInput>);
  h.output_slot_bytes = sizeof(SeqlockSlot<ShmForceOutput>);
  h.total_bytes = sizeof(ShmSegment);
  h.daemon_pid.store(getpid());
  std::atomic_thread_fence(std::memory_order_release);
  std::memcpy(h.magic, kMagic, sizeof kMagic);  // last: a reader sees the magic only when ready
  return MappedSegment(name, segment, true);
}

MappedSegment MappedSegment::Open(const std::string& name) {
  const int fd = shm_open(name.c_str(), O_RDWR | O_CLOEXEC, 0);
  HAPTICSIM_THROW_UNLESS(fd >= 0, "cannot open shared memory " + name + ": " + Why() +
                                      " (is hapticsimd running with [shm] enabled = true, and "
                                      "is this process in its group?)");
  struct stat info {};
  fstat(fd, &info);
  if (static_cast<size_t>(info.st_size) < sizeof(ShmHeader)) {
    close(fd);
    throw Error("shared memory " + name + " is too small to be hapticsimd's (" +
                std::to_string(info.st_size) + " bytes)");
  }
  if (static_cast<size_t>(info.st_size) != sizeof(ShmSegment)) {
    close(fd);
    throw Error("shared memory " + name + " has " + std::to_string(info.st_size) +
                " bytes; this client expects " + std::to_string(sizeof(ShmSegment)) +
                " (another layout version?)");
  }
  void* memory = mmap(nullptr, sizeof(ShmSegment), PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
  close(fd);
  HAPTICSIM_THROW_UNLESS(memory != MAP_FAILED, "cannot map " + name + ": " + Why());
  auto* segment = static_cast<ShmSegment*>(memory);
  const ShmHeader& h = segment->header;
  std::string problem;
  if (std::memcmp(h.magic, kMagic, sizeof kMagic) != 0) {
    problem = "has no hapticsim signature (not hapticsimd's, or not ready yet)";
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
    throw Error("shared memory " + name + " " + problem);
  }
  return MappedSegment(name, segment, false);
}

MappedSegment::MappedSegment(MappedSegment&& other) noexcept
    : name_(std::move(other.name_)), segment_(other.segment_), owner_(other.owner_) {
  other.segment_ = nullptr;
}

MappedSegment::~MappedSegment() {
  if (!segment_) return;
  if (owner_) segment_->header.daemon_pid.store(0);
  munmap(segment_, sizeof(ShmSegment));
  if (owner_) shm_unlink(name_.c_str());
}

}  // namespace hapticsim::shm
