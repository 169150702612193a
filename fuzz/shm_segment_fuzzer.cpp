// Fuzz target: a shared segment written by someone else. The fuzzer's bytes overwrite part of a
// well-formed segment image (the first two bytes choose where), which is then put in a real
// memory file, sealed when the third byte is even, and adopted as a driver adopts what it is
// handed (MappedSegment::Adopt checks the seals, the size and the header); when it maps, the
// device-input slot is read as the daemon reads it (a torn or half-written slot reads as nothing)
// and checked by the InputGuard.
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

// A surface of 3 nodes: a deformation area small enough for the fuzzer to reach every byte.
constexpr std::uint32_t kNodes = 3;

// A well-formed image, as hapticsimd creates it.
std::vector<std::uint8_t> GoodImage() {
  std::vector<std::uint8_t> image(shm::SegmentBytes(kNodes));
  shm::FormatSegment(image.data(), 0, kNodes);
  return image;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
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
  const int fd = memfd_create("hapticsim-fuzz", MFD_CLOEXEC | MFD_ALLOW_SEALING);
  if (fd < 0) __builtin_trap();
  if (!image.empty() &&
      pwrite(fd, image.data(), image.size(), 0) != static_cast<ssize_t>(image.size())) {
    __builtin_trap();
  }
  const bool sealed = size < 3 || data[2] % 2 == 0;
  if (sealed && fcntl(fd, F_ADD_SEALS, F_SEAL_SHRINK | F_SEAL_GROW | F_SEAL_SEAL) != 0) {
    __builtin_trap();
  }
  try {
    shm::MappedSegment mapping = shm::MappedSegment::Adopt(fd, "the fuzzer");  // closes fd
    if (!sealed) __builtin_trap();  // an unsealed segment must be refused
    // The input ring read as the daemon reads it: at most kInputSlots, whatever the index says.
    hapticsim::InputGuard guard({0.25, 0.25, 0.25}, 0.05, 5.0);
    shm::ShmInputReader reader;
    const int read = reader.ReadNew(mapping.segment(), [&](const shm::ShmDeviceInput& input) {
      const auto verdict = guard.Check(
          input.seq, {input.position_m[0], input.position_m[1], input.position_m[2]}, 1'000'000);
      if (verdict == hapticsim::InputRejection::kAccepted && !std::isfinite(input.position_m[0])) {
        __builtin_trap();
      }
    });
    if (read > shm::kInputSlots) __builtin_trap();
    // The deformed surface read as a viewer reads it: inside the mapping whatever its words say.
    shm::ShmDeformationArea area = mapping.deformation();
    std::vector<std::int32_t> ids(area.nodes());
    std::vector<double> displacement(3 * std::size_t{area.nodes()});
    shm::ShmDeformationFrame frame;
    (void)area.Read(&frame, ids.data(), displacement.data());
    // And written as the daemon writes it, over whatever the driver left in its words.
    area.Write(size > 0 ? std::int64_t{data[0]} : 0, frame, ids.data(), displacement.data());
  } catch (const hapticsim::Error&) {
  }
  return 0;
}
