// Writes the seed corpus of every fuzz target into DIR/<target>/ (how fuzz/corpus/ was made):
// well-formed inputs the fuzzer mutates from, so it starts past the first checks.
// Usage: hapticsim_fuzz_seeds DIR
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "core/errormap/error_map.hpp"
#include "core/errormap/error_map_file.hpp"
#include "core/scene/scene_toml.hpp"
#include "daemon/daemon_config.hpp"
#include "hapticsim/command_t.hpp"
#include "hapticsim/device_input_t.hpp"
#include "ipc/shm_layout.hpp"

namespace fs = std::filesystem;
using namespace hapticsim;

namespace {

void WriteFile(const fs::path& path, const std::string& bytes) {
  fs::create_directories(path.parent_path());
  std::ofstream(path, std::ios::binary) << bytes;
}

template <typename Message>
std::string Encoded(char channel, const Message& message) {
  std::string bytes(static_cast<size_t>(message.getEncodedSize()) + 1, '\0');
  bytes[0] = channel;
  message.encode(bytes.data() + 1, 0, message.getEncodedSize());
  return bytes;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s DIR\n", argv[0]);
    return 2;
  }
  const fs::path dir(argv[1]);

  Scene scene;
  WriteFile(dir / "scene_toml/paper.toml", FormatSceneToml(scene));
  scene.adaptivity.primary_size = 3;
  scene.input.contact_node = LatticeIndex{6, 12, 3};
  WriteFile(dir / "scene_toml/adaptive.toml", FormatSceneToml(scene));

  WriteFile(dir / "daemon_config/default.toml", FormatDaemonConfig(DefaultDaemonConfig()));

  std::array<std::vector<double>, kNumMapAxes> axes = {std::vector<double>{0.40, 0.49},
                                                       {1000},
                                                       {10},
                                                       {5e3, 20e3},
                                                       {0.01},
                                                       {1.0},
                                                       {1, 2},
                                                       {2, 3},
                                                       {600, 1000},
                                                       {5, 6},
                                                       {6},
                                                       {0},
                                                       {1}};
  ErrorMap map = ErrorMap::MakeGrid(axes);
  for (size_t i = 0; i < map.samples.size(); ++i) {
    MapSample& s = map.samples[i];
    s.status = i % 5 == 0 ? SampleStatus::kPredictedUnstable : SampleStatus::kOk;
    s.l2_percent = s.max_magnitude_percent = 1.0 + static_cast<double>(i);
    s.max_direction_deg = 2;
    s.reference_peak_n = 1.5;
  }
  const fs::path map_path = dir / "error_map/small.hsmap";
  fs::create_directories(map_path.parent_path());
  SaveErrorMap(map, map_path.string());

  device_input_t input{};
  input.seq = 7;
  input.position[0] = input.position[1] = 0.125;
  input.position[2] = 0.004;
  WriteFile(dir / "lcm_messages/device_input", Encoded(0, input));
  command_t command{};
  command.command = command_t::SET_ERROR_TARGET;
  command.error_target_percent = 5;
  WriteFile(dir / "lcm_messages/set_error_target", Encoded(1, command));
  command.command = command_t::PIN_CONFIGURATION;
  command.primary_size = 3, command.secondary_lod = 2, command.secondary_rate_hz = 800;
  WriteFile(dir / "lcm_messages/pin_configuration", Encoded(1, command));

  // shm_segment: two bytes of offset, then the bytes written there.
  WriteFile(dir / "shm_segment/as_created", std::string("\0\0", 2));
  shm::ShmDeviceInput slot_value;
  slot_value.seq = 3;
  slot_value.position_m[0] = slot_value.position_m[1] = 0.125;
  // The ring's newest write is number 0, and slot 0 holds it.
  std::string input_slot(2, '\0');
  const size_t offset = offsetof(shm::ShmSegment, newest_input);
  input_slot[0] = static_cast<char>(offset >> 8), input_slot[1] = static_cast<char>(offset & 255);
  const std::int64_t newest = 0;
  input_slot.append(reinterpret_cast<const char*>(&newest), sizeof newest);
  input_slot.resize(2 + offsetof(shm::ShmSegment, inputs) - offset, '\0');
  const std::uint64_t sequence = 2;  // even: a complete write
  input_slot.append(reinterpret_cast<const char*>(&sequence), sizeof sequence);
  input_slot.append(reinterpret_cast<const char*>(&slot_value), sizeof slot_value);
  WriteFile(dir / "shm_segment/written_input", input_slot);
  std::printf("seeds written to %s\n", dir.c_str());
  return 0;
}
