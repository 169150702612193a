// hapticsim device: a simulated haptic device that drives a running hapticsimd at 1 kHz and
// measures what comes back.
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <iostream>
#include <limits>

#include "core/error.hpp"
#include "core/scene/scene_model.hpp"
#include "core/scene/scene_toml.hpp"
#include "device/cpu_load.hpp"
#include "device/device_link.hpp"
#include "device/device_session.hpp"
#include "ipc/service_socket.hpp"
#include "tools/hapticsim/command.hpp"
#include "tools/hapticsim/device_report.hpp"
#include "tools/hapticsim/scene_object_front.hpp"

namespace hapticsim::cli {
namespace {

struct DeviceOptions {
  std::string transport = "lcm";
  std::string lcm_url = device::kHostLocalLcmUrl;
  std::string shm_socket = shm::kDefaultSocket;
  std::string device_channel = "HAPTIC_DEVICE", force_channel = "HAPTIC_FORCE",
              status_channel = "HAPTIC_STATUS";
  device::MotionSettings motion;
  std::vector<double> at;
  double edge_m = 0;       // --edge: the cube's edge
  std::string scene_file;  // --scene: the daemon's scene, for its object
  double duration_s = 10;
  int cpu_load = 0;
  std::vector<double> bad_input_at_s;
  bool json = false;
  std::string trace_file;  // --trace: every answer as CSV
  DeviceLimits limits;
};

// Every answer with the tip of the input it answers, as CSV (a plot of force against position).
void WriteTrace(const std::string& path, const std::vector<device::TracePoint>& trace) {
  std::ofstream out(path);
  HAPTICSIM_THROW_UNLESS(out.good(), "--trace " + path + ": cannot write it");
  out << "t_s,x_m,y_m,z_m,fx_n,fy_n,fz_n,in_contact,flags,error_percent\n";
  char row[256];
  for (const device::TracePoint& p : trace) {
    std::snprintf(row, sizeof row, "%.4f,%.6f,%.6f,%.6f,%.5f,%.5f,%.5f,%d,%d,%.4g\n", p.t_s,
                  p.position_m[0], p.position_m[1], p.position_m[2], p.force_n[0], p.force_n[1],
                  p.force_n[2], (p.flags & 1) ? 1 : 0, p.flags, p.error_percent);
    out << row;
  }
  HAPTICSIM_THROW_UNLESS(out.good(), "--trace " + path + ": writing it failed (disk full?)");
}

int Run(DeviceOptions o) {
  HAPTICSIM_THROW_UNLESS(o.edge_m == 0 || o.scene_file.empty(),
                         "--edge and --scene both give the object: use one");
  if (o.edge_m != 0) o.motion.extent_m = {o.edge_m, o.edge_m, o.edge_m};
  if (!o.scene_file.empty()) MeetSceneObject(o.scene_file, &o.motion);
  if (!o.at.empty()) {
    HAPTICSIM_THROW_UNLESS(o.at.size() == 2, "--at takes two numbers: X,Y on the front face, m");
    o.motion.at_m = {o.at[0], o.at[1]};
  } else {
    o.motion.at_m = {o.motion.extent_m[0] / 2, o.motion.extent_m[1] / 2};
  }
  HAPTICSIM_THROW_UNLESS(o.duration_s > 0, "--duration must be positive, s");
  device::DeviceMotion motion(o.motion);
  if (o.motion.kind == "replay" && o.duration_s <= 0) o.duration_s = motion.replay_periods() / 1e3;
  std::unique_ptr<device::DeviceLink> link, status_link;
  if (o.transport == "lcm") {
    link = device::MakeLcmLink(o.lcm_url, o.device_channel, o.force_channel, o.status_channel);
  } else if (o.transport == "shm") {
    link = device::MakeShmLink(o.shm_socket);
    // The daemon's status (deadlines, configuration) comes over LCM; listen when LCM is there.
    try {
      status_link = device::MakeLcmLink(o.lcm_url, o.device_channel, o.force_channel,
                                        o.status_channel, /*listen_only=*/true);
    } catch (const Error&) {
    }
  } else {
    throw Error("--transport " + o.transport + ": use lcm or shm");
  }
  device::SessionSettings settings;
  settings.duration_s = o.duration_s;
  settings.bad_input_bursts_s = o.bad_input_at_s;
  settings.keep_trace = !o.trace_file.empty();
  if (o.motion.kind == "press") {
    settings.press_period_inputs = std::lround(settings.rate_hz / o.motion.frequency_hz);
  }
  device::CpuLoad load(o.cpu_load);
  const bool terminal = isatty(STDERR_FILENO);
  const device::SessionReport report = device::RunSession(
      motion, *link, status_link.get(), settings, [&](const device::SessionReport& r) {
        if (!terminal) return;
        const device::SecondSummary& s = r.seconds.back();
        std::fprintf(
            stderr,
            "\rdevice %s: %3.0f / %.0f s, %lld sent, %lld answers, %lld lost; "
            "last second p99 %.0f µs, max %.0f µs   ",
            link->name().c_str(), s.t_s, o.duration_s, static_cast<long long>(r.inputs_sent),
            static_cast<long long>(r.stream.answers), static_cast<long long>(r.stream.lost_answers),
            s.latency.p99_us, s.latency.max_us);
      });
  if (terminal) std::fprintf(stderr, "\n");
  const double load_cpu_s = load.Stop();
  if (!o.trace_file.empty()) WriteTrace(o.trace_file, report.trace);
  const std::vector<std::string> exceeded = ExceededLimits(report, o.limits);
  if (o.json) {
    nlohmann::json out = ReportJson(report);
    out["transport"] = o.transport;
    out["input"] = o.motion.kind;
    out["cpu_load"] = {{"threads", o.cpu_load}, {"cpu_s", load_cpu_s}};
    out["limits_met"] = exceeded.empty();
    out["limits_exceeded"] = exceeded;
    std::cout << out.dump(2) << "\n";
  } else {
    std::cout << "Simulated device over " << o.transport << ", " << o.motion.kind << " input, "
              << o.duration_s << " s at 1 kHz:\n"
              << ReportText(report);
    if (o.cpu_load > 0) {
      char line[96];
      std::snprintf(line, sizeof line, "  cpu load                   %d busy threads, given %.1f s of CPU\n",
                    o.cpu_load, load_cpu_s);
      std::cout << line;
    }
    if (exceeded.empty()) {
      std::cout << "  limits                     met\n";
    } else {
      std::cout << "  limits                     EXCEEDED:";
      for (const std::string& name : exceeded) std::cout << " " << name;
      std::cout << "\n";
    }
  }
  if (report.stream.answers == 0) {
    std::cerr << "hapticsim device: no answer from hapticsimd over " << o.transport
              << (o.transport == "lcm" ? " on " + o.lcm_url : " at " + o.shm_socket)
              << ": is it running, with that interface enabled?\n";
    return kExitLimitsExceeded;
  }
  return exceeded.empty() ? kExitOk : kExitLimitsExceeded;
}

}  // namespace

Command AddDeviceCommand(CLI::App& parent) {
  auto options = std::make_shared<DeviceOptions>();
  CLI::App* app = parent.add_subcommand(
      "device",
      "Simulated haptic device: drive a running hapticsimd at 1 kHz over LCM or shared memory "
      "with reproducible input, and measure round-trip latency, missing and late answers, force "
      "sanity and the daemon's deadline statistics. Exit status 4 when a --max-* limit is "
      "exceeded (or nothing answered).");
  app->add_option("--transport", options->transport, "lcm or shm")->capture_default_str();
  app->add_option("--lcm-url", options->lcm_url, "LCM URL (the default stays on this host: ttl=0)")
      ->capture_default_str();
  app->add_option("--shm-socket", options->shm_socket,
                  "hapticsimd's service socket (its shm.socket), for --transport shm")
      ->capture_default_str();
  app->add_option("--device-channel", options->device_channel)->capture_default_str();
  app->add_option("--force-channel", options->force_channel)->capture_default_str();
  app->add_option("--status-channel", options->status_channel)->capture_default_str();
  app->add_option("--input", options->motion.kind,
                  "press (the paper's), sine, walk (seeded random walk with touch-downs at "
                  "different points), stroke (in at --at, along +x by --length, out and back: "
                  "for a sliding tool, contact.model = \"proxy\") or replay (an LCM log)")
      ->capture_default_str();
  app->add_option("--amplitude", options->motion.amplitude_m,
                  "Press depth, sine amplitude, deepest walk press, stroke depth, m")
      ->capture_default_str();
  app->add_option("--length", options->motion.stroke_length_m,
                  "How far a stroke slides along +x, m")
      ->capture_default_str();
  app->add_option("--trace", options->trace_file,
                  "Write every answer as CSV: the input's time and tip (m), the force (N), "
                  "in contact, flags and the error the daemon reported, %")
      ->capture_default_str();
  app->add_option("--frequency", options->motion.frequency_hz,
                  "Press, sine and stroke frequency, Hz")
      ->capture_default_str();
  app->add_option("--at", options->at,
                  "Press, sine and stroke start point over the object's front: X,Y in m "
                  "(default: the middle of its box)")
      ->delimiter(',')
      ->expected(2);
  app->add_option("--edge", options->edge_m, "The daemon's cube edge, m (default 0.25)");
  app->add_option("--scene", options->scene_file,
                  "The daemon's scene file ([scene] file in its config): the device presses, "
                  "sines, strokes and walks on its object's front (its least z over each point; "
                  "z = 0 on a block), instead of --edge's cube");
  app->add_option("--seed", options->motion.seed, "Random walk seed")->capture_default_str();
  app->add_option("--walk-speed", options->motion.walk_speed_m_per_s, "Random walk top speed, m/s")
      ->capture_default_str();
  app->add_option("--replay", options->motion.replay_path,
                  "LCM log (lcm-logger) whose device inputs to replay (with --input replay)");
  app->add_option("--replay-channel", options->motion.replay_channel)->capture_default_str();
  app->add_option("--duration", options->duration_s, "Seconds to run")->capture_default_str();
  app->add_option("--bad-input-at", options->bad_input_at_s,
                  "Inject a burst of bad input at these times, s (NaN, far outside, a jump, an "
                  "old seq; on LCM also a message of no type and one of another type), then "
                  "0.1 s of silence (stale input)")
      ->delimiter(',');
  app->add_option("--cpu-load", options->cpu_load,
                  "Busy threads at normal priority in this process for the whole run (a user's "
                  "desktop)")
      ->capture_default_str()
      ->check(CLI::Range(0, 64));
  app->add_flag("--json", options->json, "Print the summary as JSON");
  app->add_option("--max-p99-us", options->limits.p99_us, "Limit: p99 round trip, µs");
  app->add_option("--max-latency-us", options->limits.max_latency_us,
                  "Limit: worst round trip, µs");
  app->add_option("--max-unanswered", options->limits.unanswered, "Limit: inputs never answered");
  app->add_option("--max-late-percent", options->limits.late_percent,
                  "Limit: answers later than one period, % of inputs");
  app->add_option("--max-lost", options->limits.lost, "Limit: daemon answers never received");
  app->add_option("--max-force-step", options->limits.force_step_n,
                  "Limit: largest force change between periods in contact, N");
  return {app, [options] { return Run(*options); }};
}

}  // namespace hapticsim::cli
