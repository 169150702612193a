// Fuzz target: the daemon's answer as a driver receives it on the service socket. The first byte
// chooses what comes with the message (nothing, a sealed memory file holding a well-formed segment
// with the fuzzer's overlay bytes over its header, the same unsealed, or a plain pipe); the second
// is the length of the message text that follows; the bytes after the text are the overlay. It is
// sent over a real Unix socket pair and read by ReadSessionAnswer, as ConnectToService reads it.
// Whatever comes, a segment is mapped only from the exact greeting with a sealed file of the right
// layout, and no descriptor is left open.
#include <fcntl.h>
#include <sys/mman.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <new>
#include <string>

#include "core/error.hpp"
#include "ipc/service_socket.hpp"

namespace shm = hapticsim::shm;

namespace {

std::size_t OpenDescriptors() {
  std::size_t count = 0;
  for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator("/proc/self/fd")) {
    ++count;
  }
  return count;
}

// A segment file as hapticsimd makes one, its first bytes replaced by `overlay`.
int SegmentFile(const std::string& overlay, bool sealed) {
  const int fd = memfd_create("hapticsim-fuzz", MFD_CLOEXEC | MFD_ALLOW_SEALING);
  const std::size_t bytes = shm::SegmentBytes(0);
  if (fd < 0 || ftruncate(fd, static_cast<off_t>(bytes)) != 0) __builtin_trap();
  void* memory = mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
  if (memory == MAP_FAILED) __builtin_trap();
  shm::FormatSegment(memory, 1);
  std::memcpy(memory, overlay.data(), std::min(overlay.size(), sizeof(shm::ShmHeader)));
  munmap(memory, bytes);
  if (sealed && fcntl(fd, F_ADD_SEALS, F_SEAL_SHRINK | F_SEAL_GROW | F_SEAL_SEAL) != 0) {
    __builtin_trap();
  }
  return fd;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 2) return 0;
  const int attach = data[0] % 4;
  const std::size_t length = std::min<std::size_t>(data[1], size - 2);
  const std::string text(reinterpret_cast<const char*>(data + 2), length);
  const std::string overlay(reinterpret_cast<const char*>(data + 2 + length), size - 2 - length);
  const std::size_t open_before = OpenDescriptors();
  int ends[2];
  if (socketpair(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0, ends) != 0) __builtin_trap();
  int passed = -1;
  if (attach == 1 || attach == 2) passed = SegmentFile(overlay, attach == 1);
  int pipe_ends[2] = {-1, -1};
  if (attach == 3) {
    if (pipe(pipe_ends) != 0) __builtin_trap();
    passed = pipe_ends[0];
  }
  // An empty message cannot carry a descriptor on a SEQPACKET socket: send a hang-up instead.
  if (!text.empty()) shm::SendMessage(ends[0], text, passed);
  if (passed >= 0) close(passed);
  if (pipe_ends[1] >= 0) close(pipe_ends[1]);
  close(ends[0]);
  bool mapped = false;
  try {
    shm::MappedSegment segment = shm::ReadSessionAnswer(ends[1], "the fuzzer", 0);
    mapped = true;
    if (text != shm::SessionGreeting() || attach != 1) __builtin_trap();
  } catch (const hapticsim::Error&) {
  }
  close(ends[1]);
  // The daemon's own answer: the greeting with an untouched sealed segment must be mapped.
  if (!mapped && text == shm::SessionGreeting() && attach == 1 && overlay.empty()) {
    __builtin_trap();
  }
  if (OpenDescriptors() != open_before) __builtin_trap();  // a descriptor leaked
  return 0;
}
