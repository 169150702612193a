// press_cpp: the same press as press_c, in C++ on the header-only client (hapticsim::ipc), with
// the contact point taken from the simulation core (hapticsim::core) and the flag from the LCM
// types (hapticsim::lcmtypes). Exit status as press_c's.
//
//   press_cpp [--socket PATH]
#include <time.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <hapticsim/force_feedback_t.hpp>
#include <string>

#include "core/error.hpp"
#include "core/scene/scene.hpp"
#include "ipc/shm_device_client.hpp"

namespace {

std::int64_t NowNs() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

void SleepUntil(std::int64_t at_ns) {
  const timespec at{static_cast<time_t>(at_ns / 1'000'000'000),
                    static_cast<long>(at_ns % 1'000'000'000)};
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &at, nullptr) != 0) {
  }
}

}  // namespace

int main(int argc, char** argv) {
  std::string socket_path = hapticsim::shm::kDefaultSocket;
  if (argc == 3 && std::strcmp(argv[1], "--socket") == 0) socket_path = argv[2];
  // Where the default scene is touched, and which way is in: from the core.
  const hapticsim::Scene scene;
  const hapticsim::LatticeIndex node = hapticsim::ContactNode(scene);
  const std::array<double, 3> inward = hapticsim::InwardNormal(scene.mesh, node);
  const double spacing_m = scene.mesh.edge_m / (scene.mesh.nodes - 1);
  try {
    hapticsim::shm::ShmDeviceClient client(socket_path);
    const int periods = 2000;
    int answered = 0, in_contact = 0;
    double peak_n = 0;
    const std::int64_t start = NowNs() + 1'000'000;
    for (int seq = 1; seq <= periods; ++seq) {
      const std::int64_t release = start + std::int64_t{seq - 1} * 1'000'000;
      SleepUntil(release);
      const double t = static_cast<double>(seq) / periods;
      const double depth_m = t < 0.2 ? -0.002 : 0.005 * (1 - std::cos(2 * M_PI * (t - 0.2) / 0.8));
      std::array<double, 3> tip{};
      for (int c = 0; c < 3; ++c) tip[c] = node[c] * spacing_m + depth_m * inward[c];
      client.WriteInput(seq, release / 1000, tip);
      SleepUntil(release + 900'000);
      hapticsim::shm::ShmForceOutput force;
      if (client.Source(NowNs()) != hapticsim::shm::ForceSource::kLive) continue;
      if (!client.ReadForce(&force) || force.seq < 0) continue;
      ++answered;
      if (force.flags & hapticsim::force_feedback_t::FLAG_IN_CONTACT) ++in_contact;
      peak_n = std::max(peak_n, std::hypot(force.force_n[0], force.force_n[1], force.force_n[2]));
    }
    std::printf(
        "press_cpp: contact node (%d, %d, %d); %d periods: %d answered, %d in contact; "
        "peak force %.3f N\n",
        node[0], node[1], node[2], periods, answered, in_contact, peak_n);
    return answered >= periods * 9 / 10 && in_contact > 0 && peak_n > 0.5 ? 0 : 1;
  } catch (const hapticsim::Error& e) {
    std::fprintf(stderr, "press_cpp: %s\n", e.what());  // says what to fix
    return 2;
  }
}
