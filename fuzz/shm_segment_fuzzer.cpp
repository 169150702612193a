// Fuzz target: a shared-memory segment written by someone else. The fuzzer's bytes overwrite part
// of a well-formed segment image (the first two bytes choose where), which is then put in real
// POSIX shared memory and opened as a driver opens it (MappedSegment::Open checks the size and
// the header); when it opens, the device-input slot is read as the daemon reads it (a torn or
// half-written slot reads as nothing) and checked by the InputGuard.
#include <fcntl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <new>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "daemon/input_guard.hpp"
#include "ipc/shm_segment.hpp"

namespace shm = hapticsim::shm;

namespace {

// A well-formed image, as hapticsimd creates it.
std::vector<std::uint8_t> GoodImage() {
  std::vector<std::uint8_t> image(sizeof(shm::ShmSegment));
  auto* segment = new (image.data()) shm::ShmSegment();
  shm::ShmHeader& h = segment->header;
  std::memcpy(h.magic, shm::kMagic, sizeof shm::kMagic);
  h.layout_version = shm::kLayoutVersion;
  h.header_bytes = sizeof(shm::ShmHeader);
  h.input_slot_bytes = sizeof(hapticsim::SeqlockSlot<shm::ShmDeviceInput>);
  h.output_slot_bytes = sizeof(hapticsim::SeqlockSlot<shm::ShmForceOutput>);
  h.total_bytes = sizeof(shm::ShmSegment);
  return image;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string name = "/hapticsim-fuzz-" + std::to_string(getpid());
  static const std::vector<std::uint8_t> good = GoodImage();
  std::vector<std::uint8_t> image = good;
  if (size >= 2) {
    // Where the bytes go; past the end they lengthen the segment (a wrong size must be refused).
    const std::size_t at = (std::size_t{data[0]} << 8 | data[1]) % (image.size() + 1);
    const std::size_t n = size - 2;
    if (at + n > image.size()) image.resize(at + n);
    std::memcpy(image.data() + at, data + 2, n);
  } else {
    image.resize(size);  // a segment too small to hold a header
  }
  const int fd = shm_open(name.c_str(), O_RDWR | O_CREAT | O_TRUNC, 0600);
  if (fd < 0) __builtin_trap();
  if (!image.empty() &&
      pwrite(fd, image.data(), image.size(), 0) != static_cast<ssize_t>(image.size())) {
    __builtin_trap();
  }
  close(fd);
  try {
    shm::MappedSegment mapping = shm::MappedSegment::Open(name);
    // The input ring read as the daemon reads it: at most kInputSlots, whatever the index says.
    hapticsim::InputGuard guard(hapticsim::MeshSettings{}, 0.05, 5.0);
    shm::ShmInputReader reader;
    const int read = reader.ReadNew(mapping.segment(), [&](const shm::ShmDeviceInput& input) {
      const auto verdict = guard.Check(
          input.seq, {input.position_m[0], input.position_m[1], input.position_m[2]}, 1'000'000);
      if (verdict == hapticsim::InputRejection::kAccepted && !std::isfinite(input.position_m[0])) {
        __builtin_trap();
      }
    });
    if (read > shm::kInputSlots) __builtin_trap();
  } catch (const hapticsim::Error&) {
  }
  shm_unlink(name.c_str());
  return 0;
}
