// hapticsim-shm-client: a device driver's side of the shared-memory interface, as an example for
// driver writers and a probe for tests. At 1 kHz (absolute-time sleeps) it moves the tool tip
// from above the surface into the object at the paper's contact point and back, reads the force
// for every period, and prints a JSON summary. Every answer the daemon wrote is read from the
// output ring (not only the newest), so the summary can tell which inputs were never answered.
//
//   hapticsim-shm-client [--socket /run/hapticsim/hapticsimd.sock] [--duration 2] [--depth 0.01]
#include <time.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <set>
#include <thread>
#include <vector>

#include "core/error.hpp"
#include "ipc/shm_device_client.hpp"

namespace {

std::int64_t NowNs() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

}  // namespace

int main(int argc, char** argv) {
  std::string socket_path = hapticsim::shm::kDefaultSocket;
  double duration_s = 2.0, depth_m = 0.01, edge_m = 0.25;
  CLI::App app{
      "hapticsim-shm-client: drive hapticsimd through shared memory at 1 kHz and "
      "summarise its answers as JSON",
      "hapticsim-shm-client"};
  app.add_option("--socket", socket_path, "hapticsimd's service socket (its shm.socket)")
      ->capture_default_str();
  app.add_option("--duration", duration_s, "Seconds to run")->capture_default_str();
  app.add_option("--depth", depth_m, "Deepest press into the object, m")->capture_default_str();
  app.add_option("--edge", edge_m, "Cube edge of the daemon's scene, m")->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  try {
    hapticsim::shm::ShmDeviceClient client(socket_path);
    const std::int64_t periods = std::llround(duration_s * 1000);
    std::int64_t answered_same_period = 0, nonfinite = 0, in_contact = 0, stale = 0;
    std::int64_t max_lag = 0, last_seen = -1, out_of_order = 0, no_source = 0;
    double max_push_back = 0;
    std::set<std::int64_t> seen;
    // Each input is answered by the period that first used it: every seq from an answer's
    // first_seq to its seq. Read from the ring after each period, and once more at the end.
    std::vector<bool> answered(static_cast<std::size_t>(periods) + 1, false);
    std::int64_t last_period_read = -1;
    auto mark_answered = [&] {
      last_period_read =
          client.ReadForcesSince(last_period_read, [&](const hapticsim::shm::ShmForceOutput& f) {
            for (std::int64_t s = std::max<std::int64_t>(f.first_seq, 1);
                 s <= std::min(f.seq, periods); ++s) {
              answered[static_cast<std::size_t>(s)] = true;
            }
          });
    };
    const std::int64_t start = NowNs() + 1'000'000;
    for (std::int64_t seq = 1; seq <= periods; ++seq) {
      const std::int64_t release = start + (seq - 1) * 1'000'000;
      timespec at{static_cast<time_t>(release / 1'000'000'000),
                  static_cast<long>(release % 1'000'000'000)};
      while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &at, nullptr) == EINTR) {
      }
      // Above the surface for the first fifth, then a press of depth_m and back (1 Hz shape).
      const double t = static_cast<double>(seq) / periods;
      const double z =
          t < 0.2 ? -0.002 : depth_m * 0.5 * (1 - std::cos(2 * M_PI * (t - 0.2) / 0.8));
      client.WriteInput(seq, release / 1000, {edge_m / 2, edge_m / 2, z});
      // Read the answer just before the next period.
      const std::int64_t read_at = release + 900'000;
      timespec then{static_cast<time_t>(read_at / 1'000'000'000),
                    static_cast<long>(read_at % 1'000'000'000)};
      while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &then, nullptr) == EINTR) {
      }
      // A driver renders zero when no daemon is answering: the segment keeps the last force.
      if (client.Source(NowNs()) == hapticsim::shm::ForceSource::kNone) {
        ++no_source;
        continue;
      }
      mark_answered();
      hapticsim::shm::ShmForceOutput force;
      if (!client.ReadForce(&force) || force.seq < 0) continue;
      if (force.seq == seq) ++answered_same_period;
      if (force.seq < last_seen) ++out_of_order;
      last_seen = force.seq;
      seen.insert(force.seq);
      max_lag = std::max(max_lag, seq - force.seq);
      if (!std::isfinite(force.force_n[0] + force.force_n[1] + force.force_n[2])) ++nonfinite;
      if (force.flags & 1) ++in_contact;
      if (force.flags & 8) ++stale;
      max_push_back = std::max(max_push_back, -force.force_n[2]);
    }
    // The last input's answer: the daemon's next period, or later if it was held up (up to 1 s).
    for (int wait_ms = 0; wait_ms < 1000 && !answered.back(); wait_ms += 5) {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
      mark_answered();
    }
    const auto inputs_answered = std::count(answered.begin() + 1, answered.end(), true);
    std::printf(
        "{\"periods\": %lld, \"inputs_answered\": %lld, \"answered_same_period\": %lld, "
        "\"distinct_seqs_answered\": %zu, "
        "\"max_lag_periods\": %lld, \"out_of_order\": %lld, \"nonfinite_forces\": %lld, "
        "\"in_contact_periods\": %lld, \"stale_periods\": %lld, \"max_push_back_N\": %.6g, "
        "\"no_force_source_periods\": %lld, \"daemon_running\": %s}\n",
        static_cast<long long>(periods), static_cast<long long>(inputs_answered),
        static_cast<long long>(answered_same_period), seen.size(),
        static_cast<long long>(max_lag), static_cast<long long>(out_of_order),
        static_cast<long long>(nonfinite), static_cast<long long>(in_contact),
        static_cast<long long>(stale), max_push_back, static_cast<long long>(no_source),
        client.DaemonRunning() ? "true" : "false");
    return 0;
  } catch (const hapticsim::Error& e) {
    std::fprintf(stderr, "hapticsim-shm-client: error: %s\n", e.what());
    return 2;
  }
}
