// Fuzz target: the error-map loader (hapticsim sweep's binary file → ErrorMap, and the daemon's
// lookup table). The bytes are handed over as a file, as the daemon reads one. A fuzzing build
// skips the section checksums, so the fuzzer reaches the parsers behind them.
#include <sys/mman.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <string>

#include "core/error.hpp"
#include "core/errormap/error_lookup.hpp"
#include "core/errormap/error_map_file.hpp"

namespace {

// One in-memory file per process, rewritten for every input.
const std::string& MapPath() {
  static const std::string path = [] {
    const int fd = memfd_create("hapticsim-fuzz-map", 0);
    if (fd < 0) __builtin_trap();
    return "/proc/self/fd/" + std::to_string(fd);
  }();
  return path;
}

void Write(const std::string& path, const std::uint8_t* data, std::size_t size) {
  const int fd = std::stoi(path.substr(path.rfind('/') + 1));
  if (ftruncate(fd, 0) != 0 || pwrite(fd, data, size, 0) != static_cast<ssize_t>(size)) {
    __builtin_trap();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string& path = MapPath();
  Write(path, data, size);
  try {
    const hapticsim::ErrorMap map = hapticsim::LoadErrorMap(path);
    if (map.grid && map.samples.size() != map.GridSize()) __builtin_trap();
  } catch (const hapticsim::Error&) {
  }
  try {
    const hapticsim::ErrorLookup lookup =
        hapticsim::LoadErrorLookup(path, hapticsim::ErrorField::kMagnitude);
    // Looking up anywhere — inside, outside, at NaN — must answer without crashing.
    hapticsim::MapPoint point{};
    for (std::size_t i = 0; i < point.size() && i < size; ++i) point[i] = data[i] * 1000.0 - 5.0;
    lookup.Lookup(hapticsim::LookupQuery::At(point));
  } catch (const hapticsim::Error&) {
  }
  return 0;
}
