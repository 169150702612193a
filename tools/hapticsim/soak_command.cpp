// hapticsim soak: hapticsimd and the simulated device together for a long run, in a private
// network namespace, with the checks its users care about.
#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <mutex>
#include <sstream>
#include <thread>

#include "core/error.hpp"
#include "core/regions/stability_stress.hpp"
#include "daemon/sandbox_check.hpp"
#include "device/cpu_load.hpp"
#include "device/device_link.hpp"
#include "device/device_session.hpp"
#include "ipc/control_client.hpp"
#include "tools/hapticsim/command.hpp"
#include "tools/hapticsim/deformation_watch.hpp"
#include "tools/hapticsim/device_report.hpp"
#include "tools/hapticsim/line_chart.hpp"
#include "tools/hapticsim/scene_object_front.hpp"

namespace hapticsim::cli {
namespace {

namespace fs = std::filesystem;
constexpr const char* kInNetnsVariable = "HAPTICSIM_SOAK_IN_PRIVATE_NETNS";

struct SoakOptions {
  double duration_s = 60;
  double warm_up_s = -1;  // default: a tenth of the run, at least 5 s
  std::string daemon;
  std::string error_map;
  std::string scene;  // --scene: the object served and touched (default: the paper's cube)
  std::string report_dir = "soak-report";
  std::string input = "walk";
  unsigned seed = 1;
  double max_lcm_loss_percent = 1.0;
  double max_rss_growth_kib = 2048;
  int cpu_load = 0;               // busy threads beside daemon and device, normal priority
  double max_force_step_n = 1.0;  // largest force change between answers in contact
  double min_answered_percent = 95;
  bool no_port_guard = false;  // hapticsimd --no-port-guard: the coupling alone behind the port
  double switch_every_s = 0;   // pin another configuration this often (0: never)
  double deformation_rate_hz = 60;  // the daemon's [deformation] rate_hz, watched on LCM
  bool json = false;
};

// The configurations a soak with --switch-every pins in turn: they differ in every parameter, so
// each switch replaces every region.
constexpr const char* kSoakPins[] = {"pin 2 3 600", "pin 3 2 1000"};

// Pins kSoakPins in turn on the daemon's control socket every `every_s` seconds until `running`
// goes false (hapticsim ctl's requests, as a user would send them): the answers that began "ok:"
// and those that did not.
struct Switcher {
  std::atomic<int> ok{0}, refused{0};
  std::thread thread;
  void Start(const std::string& socket, double every_s, const std::atomic<bool>& running) {
    thread = std::thread([this, socket, every_s, &running] {
      auto next = std::chrono::steady_clock::now();
      for (int k = 0; running; ++k) {
        next += std::chrono::milliseconds(static_cast<long>(every_s * 1000));
        while (running && std::chrono::steady_clock::now() < next) {
          std::this_thread::sleep_for(std::chrono::milliseconds(50));
        }
        if (!running) return;
        try {
          const std::string answer = shm::SendControlRequest(socket, kSoakPins[k % 2], 5000);
          (answer.rfind("ok:", 0) == 0 ? ok : refused).fetch_add(1);
        } catch (const Error&) {
          refused.fetch_add(1);
        }
      }
    });
  }
  void Join() {
    if (thread.joinable()) thread.join();
  }
};

struct ResourceSample {
  double t_s = 0;
  double rss_kib = 0;
  double cpu_percent = 0;
};

fs::path SelfPath() { return fs::read_symlink("/proc/self/exe"); }

std::string DefaultDaemon() {
  const fs::path here = SelfPath().parent_path();
  for (const fs::path& candidate : {here / "hapticsimd", here / ".." / "daemon" / "hapticsimd"}) {
    if (fs::exists(candidate)) return fs::canonical(candidate).string();
  }
  throw Error("hapticsimd not found next to " + SelfPath().string() + ": give it with --daemon");
}

// The soak's own LCM must never reach a real network: run again inside a user + network
// namespace of our own (loopback only, a multicast route on it), as the tests do.
[[noreturn]] void ReexecInPrivateNetns(int argc, char** argv) {
  setenv(kInNetnsVariable, "1", 1);
  std::vector<std::string> args{
      "unshare",
      "--user",
      "--map-root-user",
      "--net",
      "sh",
      "-c",
      "ip link set lo up && ip route add 224.0.0.0/4 dev lo src 127.0.0.1 && "
      "exec \"$@\"",
      "sh",
      SelfPath().string()};
  for (int i = 1; i < argc; ++i) args.emplace_back(argv[i]);
  std::vector<char*> raw;
  for (std::string& a : args) raw.push_back(a.data());
  raw.push_back(nullptr);
  execvp("unshare", raw.data());
  throw Error(std::string("cannot start a private network namespace (unshare: ") +
              std::strerror(errno) + "); user namespaces must be allowed");
}

bool ReadProc(pid_t pid, double* rss_kib, double* cpu_ticks) {
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  std::string key;
  *rss_kib = 0;
  while (status >> key) {
    if (key == "VmRSS:") {
      status >> *rss_kib;
      break;
    }
    status.ignore(1 << 12, '\n');
  }
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string line;
  if (!std::getline(stat, line)) return false;
  // Fields after the command name (which may hold spaces): state is field 3; utime 14, stime 15.
  std::istringstream rest(line.substr(line.rfind(')') + 2));
  std::string field;
  double utime = 0, stime = 0;
  for (int f = 3; f <= 15 && rest >> field; ++f) {
    if (f == 14) utime = std::stod(field);
    if (f == 15) stime = std::stod(field);
  }
  *cpu_ticks = utime + stime;
  return *rss_kib > 0;
}

std::string TailOf(const std::string& path, std::size_t lines) {
  std::ifstream in(path);
  std::vector<std::string> all;
  for (std::string line; std::getline(in, line);) all.push_back(line);
  std::string out;
  for (std::size_t i = all.size() > lines ? all.size() - lines : 0; i < all.size(); ++i) {
    out += "  " + all[i] + "\n";
  }
  return out;
}

void WriteHtml(const fs::path& path, const nlohmann::json& summary,
               const device::SessionReport& report, const std::vector<ResourceSample>& resources) {
  std::vector<double> t, median, p99, max;
  for (const device::SecondSummary& s : report.seconds) {
    t.push_back(s.t_s);
    median.push_back(s.latency.median_us);
    p99.push_back(s.latency.p99_us);
    max.push_back(s.latency.max_us);
  }
  std::vector<double> rt, rss, cpu;
  for (const ResourceSample& r : resources) {
    rt.push_back(r.t_s);
    rss.push_back(r.rss_kib / 1024);
    cpu.push_back(r.cpu_percent);
  }
  std::ofstream out(path);
  out << "<!doctype html><html><head><meta charset='utf-8'><title>hapticsim soak</title>"
      << "<style>body{font-family:sans-serif;max-width:800px;margin:2em auto}"
      << "pre{background:#f6f6f6;padding:1em;overflow:auto}</style></head><body>"
      << "<h1>hapticsimd soak: " << (summary["passed"].get<bool>() ? "passed" : "FAILED") << "</h1>"
      << LineChartSvg("Round trip, input sent to force received, per second", "time (s)", "µs", t,
                      {{"median", median}, {"p99", p99}, {"max", max}})
      << LineChartSvg("hapticsimd resident memory", "time (s)", "MiB", rt, {{"RSS", rss}})
      << LineChartSvg("hapticsimd CPU", "time (s)", "% of one core", rt, {{"CPU", cpu}})
      << "<h2>Summary</h2><pre>" << summary.dump(2) << "</pre></body></html>\n";
}

int RunSoak(const SoakOptions& o) {
  HAPTICSIM_THROW_UNLESS(o.duration_s >= 5, "--duration must be at least 5 s");
  const double warm_up = o.warm_up_s >= 0 ? o.warm_up_s : std::max(5.0, o.duration_s / 10);
  HAPTICSIM_THROW_UNLESS(warm_up < o.duration_s, "--warm-up must be shorter than --duration");
  const std::string daemon = o.daemon.empty() ? DefaultDaemon() : o.daemon;
  const fs::path dir = fs::absolute(o.report_dir);
  fs::create_directories(dir);
  // The service socket in a directory of its own that only this user can write: the driver
  // trusts no socket others could have put in place (ipc/service_socket.hpp).
  char socket_dir[] = "/tmp/hapticsim-soak-XXXXXX";
  HAPTICSIM_THROW_UNLESS(mkdtemp(socket_dir),
                         std::string("cannot make a directory in /tmp: ") + std::strerror(errno));
  const std::string shm_socket = std::string(socket_dir) + "/hapticsimd.sock";
  const std::string control_socket = std::string(socket_dir) + "/control.sock";
  struct RemoveDir {
    std::string path;
    ~RemoveDir() {
      std::error_code ignored;
      fs::remove_all(path, ignored);
    }
  } remove_socket_dir{socket_dir};
  const fs::path config = dir / "hapticsimd.toml", log = dir / "hapticsimd.log";
  {
    std::ofstream c(config);
    c << "# written by hapticsim soak\n[shm]\nenabled = true\nsocket = \"" << shm_socket << "\"\n"
      << "[control]\nsocket = \"" << control_socket << "\"\n"
      << "[deformation]\nrate_hz = " << o.deformation_rate_hz << "\n";
    if (!o.error_map.empty()) {
      c << "[supervisor]\nerror_map = \"" << fs::absolute(o.error_map).string() << "\"\n";
    }
    if (!o.scene.empty()) c << "[scene]\nfile = \"" << fs::absolute(o.scene).string() << "\"\n";
  }
  std::cerr << "hapticsim soak: " << daemon << " for " << o.duration_s
            << " s in a private network namespace; report in " << dir.string() << "/\n";
  const pid_t pid = fork();
  if (pid == 0) {
    const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
    dup2(fd, 1), dup2(fd, 2);
    if (o.no_port_guard) {
      setenv(kSandboxVariable, "1", 1);  // hapticsimd's WhyNotASandbox: the soak started it
      execl(daemon.c_str(), daemon.c_str(), "--config", config.c_str(), "--no-port-guard", nullptr);
    } else {
      execl(daemon.c_str(), daemon.c_str(), "--config", config.c_str(), nullptr);
    }
    _exit(127);
  }
  auto stop_daemon = [&](int* status) {
    kill(pid, SIGTERM);
    for (int i = 0; i < 100; ++i) {
      if (waitpid(pid, status, WNOHANG) == pid) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    kill(pid, SIGKILL);
    waitpid(pid, status, 0);
    return false;
  };
  std::unique_ptr<device::DeviceLink> link;
  for (int i = 0; i < 300 && !link; ++i) {
    int status = 0;
    if (waitpid(pid, &status, WNOHANG) == pid) {
      throw Error("hapticsimd exited before serving; its log:\n" + TailOf(log, 20));
    }
    try {
      link = device::MakeShmLink(shm_socket);
    } catch (const Error&) {
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
  }
  if (!link) {
    int status = 0;
    stop_daemon(&status);
    throw Error("hapticsimd did not serve " + shm_socket + " within 30 s; its log:\n" +
                TailOf(log, 20));
  }
  auto monitor = device::MakeLcmLink(device::kHostLocalLcmUrl, "HAPTIC_DEVICE", "HAPTIC_FORCE",
                                     "HAPTIC_STATUS");
  DeformationWatch deformation(device::kHostLocalLcmUrl, "HAPTIC_DEFORMATION");

  // Load as on a user's desktop: busy threads at normal priority, no real-time privileges, for
  // the whole run.
  auto load = std::make_unique<device::CpuLoad>(o.cpu_load);

  std::vector<ResourceSample> resources;
  std::mutex resources_mutex;
  std::atomic<bool> sampling{true};
  Switcher switcher;
  if (o.switch_every_s > 0) switcher.Start(control_socket, o.switch_every_s, sampling);
  const auto start = std::chrono::steady_clock::now();
  std::thread sampler([&] {
    const double ticks_per_s = static_cast<double>(sysconf(_SC_CLK_TCK));
    double last_ticks = -1;
    auto last_time = start;
    while (sampling) {
      double rss = 0, ticks = 0;
      const auto now = std::chrono::steady_clock::now();
      if (ReadProc(pid, &rss, &ticks)) {
        const double dt = std::chrono::duration<double>(now - last_time).count();
        ResourceSample s{
            std::chrono::duration<double>(now - start).count(), rss,
            last_ticks >= 0 && dt > 0 ? 100 * (ticks - last_ticks) / ticks_per_s / dt : 0};
        const bool first = last_ticks < 0;  // no CPU share without a previous sample
        last_ticks = ticks, last_time = now;
        std::lock_guard lock(resources_mutex);
        if (!first) resources.push_back(s);
      }
      std::this_thread::sleep_for(std::chrono::seconds(1));
    }
  });

  device::MotionSettings motion_settings;
  motion_settings.kind = o.input;
  motion_settings.seed = o.seed;
  if (!o.scene.empty()) {  // the device's presses and walk over the scene's object, at its middle
    MeetSceneObject(o.scene, &motion_settings);
    motion_settings.at_m = {motion_settings.extent_m[0] / 2, motion_settings.extent_m[1] / 2};
  }
  device::DeviceMotion motion(motion_settings);
  device::SessionSettings settings;
  settings.duration_s = o.duration_s;
  // Bad input twice: a third and two thirds of the way.
  settings.bad_input_bursts_s = {o.duration_s / 3, 2 * o.duration_s / 3};
  const bool terminal = isatty(STDERR_FILENO);
  const device::SessionReport report = device::RunSession(
      motion, *link, monitor.get(), settings, [&](const device::SessionReport& r) {
        const device::SecondSummary& s = r.seconds.back();
        const bool plain = !terminal && static_cast<long>(s.t_s) % 10 == 0;
        if (!terminal && !plain) return;
        std::fprintf(
            stderr, "%ssoak: %4.0f / %.0f s, %lld answers, %lld lost on shm; p99 %.0f µs%s",
            terminal ? "\r" : "", s.t_s, o.duration_s, static_cast<long long>(r.stream.answers),
            static_cast<long long>(r.stream.lost_answers), s.latency.p99_us,
            terminal ? "   " : "\n");
      });
  if (terminal) std::fprintf(stderr, "\n");
  sampling = false;
  deformation.Stop();
  sampler.join();
  switcher.Join();
  const double load_cpu_s = load->Stop();
  int status = 0;
  const bool stopped_in_time = stop_daemon(&status);
  const bool clean_exit = stopped_in_time && WIFEXITED(status) && WEXITSTATUS(status) == 0;

  // Memory after the warm-up against the end.
  double rss_warm = 0, rss_end = 0, rss_max = 0, cpu_sum = 0;
  for (const ResourceSample& s : resources) {
    if (s.t_s <= warm_up || rss_warm == 0) rss_warm = s.rss_kib;
    rss_end = s.rss_kib;
    rss_max = std::max(rss_max, s.rss_kib);
    cpu_sum += s.cpu_percent;
  }
  const double rss_growth = rss_end - rss_warm;
  const device::StreamSummary lcm = report.monitor.value_or(device::StreamSummary{});
  const double lcm_loss_percent =
      lcm.answers + lcm.lost_answers > 0
          ? 100.0 * static_cast<double>(lcm.lost_answers) / (lcm.answers + lcm.lost_answers)
          : 100.0;
  nlohmann::json misses = nlohmann::json::object();
  if (report.status) {
    for (const region_status_t& r : report.status->regions) {
      misses[r.name] = {{"deadline_misses", r.deadline_misses},
                        {"periods", r.cycles},
                        {"miss_percent", r.cycles ? 100.0 * r.deadline_misses / r.cycles : 0.0},
                        {"worst_lateness_us", r.worst_lateness_us}};
    }
  }
  const std::int64_t good_inputs = report.inputs_sent;
  const double answered_percent =
      good_inputs > 0
          ? 100.0 * static_cast<double>(good_inputs - report.unanswered_inputs) / good_inputs
          : 0.0;
  const status_t last_status = report.status.value_or(status_t{});
  const nlohmann::json checks = {
      {"no_nonfinite_force", report.nonfinite_forces == 0},
      {"force_step_in_contact_within_limit", report.largest_force_step_n <= o.max_force_step_n},
      {"force_within_device_limit",
       !report.status || report.largest_force_n <= last_status.max_force_n + 1e-9},
      {"inputs_answered_shm", answered_percent >= o.min_answered_percent},
      {"no_lost_answers_shm", report.stream.lost_answers == 0},
      {"no_duplicated_answers_shm", report.stream.duplicated_answers == 0},
      {"lcm_loss_within_budget", lcm_loss_percent <= o.max_lcm_loss_percent},
      {"memory_flat_after_warm_up", rss_growth <= o.max_rss_growth_kib},
      {"answering_after_bad_input", report.answers_after_last_burst > 0},
      {"no_force_out_of_contact", report.force_out_of_contact == 0},
      {"no_energy_balance_violations",
       report.status.has_value() && last_status.energy_balance_violations == 0},
      // The runaway watch never fires on the default scene's regions: a firing there is a false
      // alarm that restarts them from rest (docs/regions.md, "The runaway watch").
      {"no_runaways", report.status.has_value() && last_status.runaways == 0},
      {"port_guard_as_asked",
       report.status.has_value() && last_status.port_guard_off == o.no_port_guard},
      // Every pin but the last switched (a pin is verified before it is applied).
      {"configurations_switched",
       o.switch_every_s <= 0 || (switcher.refused == 0 && switcher.ok >= 2 &&
                                 last_status.reconfigurations >= switcher.ok - 1)},
      // The deformed surface at its rate (a tenth may be lost to a loaded host) and finite.
      {"deformation_at_rate",
       deformation.frames() >= 0.9 * o.deformation_rate_hz * (o.duration_s - 1) &&
           deformation.Summary()["deformation_nonfinite"] == 0},
      {"daemon_stopped_cleanly", clean_exit}};
  bool passed = true;
  for (const auto& [name, ok] : checks.items()) passed = passed && ok.get<bool>();
  nlohmann::json summary = {
      {"passed", passed},
      {"checks", checks},
      {"duration_s", o.duration_s},
      {"warm_up_s", warm_up},
      {"input", o.input},
      {"nonfinite_forces", report.nonfinite_forces},
      {"lost_answers_shm", report.stream.lost_answers},
      {"duplicated_answers_shm", report.stream.duplicated_answers},
      {"answers_shm", report.stream.answers},
      {"lost_answers_lcm", lcm.lost_answers},
      {"answers_lcm", lcm.answers},
      {"lcm_loss_percent", lcm_loss_percent},
      {"max_lcm_loss_percent", o.max_lcm_loss_percent},
      {"latency_us",
       {{"median", report.latency.median_us},
        {"p99", report.latency.p99_us},
        {"p999", report.latency.p999_us},
        {"max", report.latency.max_us}}},
      {"unanswered_inputs", report.unanswered_inputs},
      {"bad_inputs_sent", report.bad_inputs_sent},
      {"rss_growth_kib", rss_growth},
      {"max_rss_growth_kib", o.max_rss_growth_kib},
      {"rss_kib", {{"after_warm_up", rss_warm}, {"end", rss_end}, {"max", rss_max}}},
      {"cpu_percent_mean", resources.empty() ? 0.0 : cpu_sum / resources.size()},
      {"deadline_misses", misses},
      {"largest_force_step_N", report.largest_force_step_n},
      {"cpu_load_threads", o.cpu_load},
      {"cpu_load_cpu_s", load_cpu_s},
      {"max_force_step_in_contact_n", report.largest_force_step_n},
      {"max_force_step_any_n", report.largest_force_step_any_n},
      {"max_force_step_one_period_n", report.largest_force_step_one_period_n},
      {"max_force_step_limit_n", o.max_force_step_n},
      {"max_force_n", report.largest_force_n},
      {"device_max_force_n", last_status.max_force_n},
      {"answered_percent_shm", answered_percent},
      {"latched_faults", last_status.latched_faults},
      {"fault_rearms", last_status.fault_rearms},
      {"force_limited_periods", last_status.force_limited_periods},
      {"port_dissipating_periods", last_status.port_dissipating_periods},
      {"port_energy_dissipated_j", last_status.port_energy_dissipated_j},
      {"port_guard_off", last_status.port_guard_off},
      {"energy_balance_violations", last_status.energy_balance_violations},
      {"runaways", last_status.runaways},
      {"interface_backlog_max_j", last_status.interface_backlog_max_j},
      {"switch_every_s", o.switch_every_s},
      {"configuration_pins_ok", switcher.ok.load()},
      {"configuration_pins_refused", switcher.refused.load()},
      {"reconfigurations", last_status.reconfigurations},
      {"daemon_exit_status", WIFEXITED(status) ? WEXITSTATUS(status) : -1},
      {"report",
       {{"json", (dir / "soak.json").string()},
        {"html", (dir / "soak.html").string()},
        {"daemon_log", log.string()}}}};
  summary["deformation_rate_hz"] = o.deformation_rate_hz;
  summary["scene"] = o.scene.empty() ? "the paper's cube" : fs::absolute(o.scene).string();
  summary.update(deformation.Summary());
  nlohmann::json full = summary;
  full["device"] = ReportJson(report);
  nlohmann::json samples = nlohmann::json::array();
  for (const ResourceSample& s : resources) {
    samples.push_back({{"t_s", s.t_s}, {"rss_kib", s.rss_kib}, {"cpu_percent", s.cpu_percent}});
  }
  full["resources"] = samples;
  std::ofstream(dir / "soak.json") << full.dump(2) << "\n";
  WriteHtml(dir / "soak.html", summary, report, resources);
  if (o.json) {
    std::cout << summary.dump(2) << "\n";
  } else {
    std::cout << "hapticsimd soak, " << o.duration_s << " s on "
              << (o.scene.empty() ? "the paper's cube" : o.scene) << " (" << o.input
              << " input over shared memory, forces also watched on LCM" << (o.cpu_load ? ", " : "")
              << (o.cpu_load ? std::to_string(o.cpu_load) + " busy threads beside, given " +
                                   std::to_string(std::lround(load_cpu_s)) + " s of CPU"
                             : "")
              << "): " << (passed ? "passed" : "FAILED") << "\n"
              << ReportText(report);
    std::printf(
        "  port guard                 largest force %.3f N (device ceiling %.3g N); largest "
        "step in contact %.3f N (limit %.3g N); %lld fault(s) latched; %lld period(s) limited; "
        "%.3g J dissipated\n",
        report.largest_force_n, last_status.max_force_n, report.largest_force_step_n,
        o.max_force_step_n, static_cast<long long>(last_status.latched_faults),
        static_cast<long long>(last_status.force_limited_periods),
        last_status.port_energy_dissipated_j);
    std::printf(
        "  coupling                   %lld period(s) with the interface backlog beyond the "
        "primary's reserve above %.3g %% of the regions' energy; largest backlog %.3g J; "
        "%lld runaway(s) taken to equal rates%s\n",
        static_cast<long long>(last_status.energy_balance_violations),
        100 * StressOutcome::kGrowingBacklog, last_status.interface_backlog_max_j,
        static_cast<long long>(last_status.runaways),
        last_status.port_guard_off ? " (port guard OFF)" : "");
    if (o.switch_every_s > 0) {
      std::printf(
          "  configurations             pinned every %.3g s: %d answered ok, %d refused; "
          "%lld reconfiguration(s)\n",
          o.switch_every_s, switcher.ok.load(), switcher.refused.load(),
          static_cast<long long>(last_status.reconfigurations));
    }
    std::printf("  shared-memory inputs answered %.2f %% (at least %.3g %%)\n", answered_percent,
                o.min_answered_percent);
    std::printf("  LCM answers lost           %lld of %lld (%.3f %%, budget %.3g %%)\n",
                static_cast<long long>(lcm.lost_answers),
                static_cast<long long>(lcm.answers + lcm.lost_answers), lcm_loss_percent,
                o.max_lcm_loss_percent);
    std::printf(
        "  resident memory            %.0f KiB after %.0f s warm-up, %.0f KiB at the end: "
        "%+.0f KiB (tolerance %.0f KiB)\n",
        rss_warm, warm_up, rss_end, rss_growth, o.max_rss_growth_kib);
    for (const auto& [name, ok] : checks.items()) {
      std::cout << "  " << (ok.get<bool>() ? "ok      " : "FAILED  ") << name << "\n";
    }
    std::cout << "  report: " << (dir / "soak.html").string() << "\n";
  }
  return passed ? kExitOk : kExitLimitsExceeded;
}

}  // namespace

Command AddSoakCommand(CLI::App& parent, int argc, char** argv) {
  auto options = std::make_shared<SoakOptions>();
  CLI::App* app = parent.add_subcommand(
      "soak",
      "Soak test: start hapticsimd and the simulated device together in a private network "
      "namespace, run for --duration (optionally beside --cpu-load busy threads), sample the "
      "daemon's memory and CPU, inject bad input, and check: no non-finite force, no force step "
      "in contact above --max-force-step, no force above the device's ceiling, at least "
      "--min-answered-percent of the inputs answered, no lost or duplicated answer on shared "
      "memory, LCM loss within budget, memory flat after the warm-up, still answering after bad "
      "input, a clean stop. Writes soak.json and soak.html. Exit status 4 when a check fails.");
  app->add_option("--duration", options->duration_s, "Seconds to run")->capture_default_str();
  app->add_option("--warm-up", options->warm_up_s,
                  "Seconds before memory must stay flat (default: a tenth of the run, ≥ 5 s)");
  app->add_option("--daemon", options->daemon,
                  "hapticsimd to run (default: the one built next to "
                  "this hapticsim)");
  app->add_option("--error-map", options->error_map, "Error map for the daemon (default: none)");
  app->add_option("--scene", options->scene,
                  "Scene file of the object the daemon serves and the device touches: its "
                  "geometry, materials, supports and contact (contact.model = \"proxy\": a tool "
                  "that slides), the device's input over its front as `hapticsim device --scene` "
                  "puts it (default: the paper's cube). --switch-every's pins must suit it")
      ->check(CLI::ExistingFile);
  app->add_option("--report", options->report_dir,
                  "Directory for soak.json, soak.html and the "
                  "daemon's log")
      ->capture_default_str();
  app->add_option("--input", options->input, "Device input: walk, press or sine")
      ->capture_default_str();
  app->add_option("--seed", options->seed, "Random walk seed")->capture_default_str();
  app->add_option("--max-lcm-loss-percent", options->max_lcm_loss_percent,
                  "Budget for forces lost on LCM, %")
      ->capture_default_str();
  app->add_option("--max-rss-growth-kib", options->max_rss_growth_kib,
                  "Tolerance for resident-memory growth after the warm-up, KiB")
      ->capture_default_str();
  app->add_option("--cpu-load", options->cpu_load,
                  "Busy threads at normal priority beside daemon and device for the whole run (a "
                  "user's desktop)")
      ->capture_default_str()
      ->check(CLI::Range(0, 64));
  app->add_option("--max-force-step", options->max_force_step_n,
                  "Largest force change between consecutive answers in contact, N")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app->add_option("--min-answered-percent", options->min_answered_percent,
                  "Shared-memory inputs that must be answered, %")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 100.0));
  app->add_flag("--no-port-guard", options->no_port_guard,
                "Run the daemon with its port guard off (hapticsimd --no-port-guard, allowed in "
                "the soak's private network namespace): the checks then show what the regions' "
                "coupling does by itself");
  app->add_option("--switch-every", options->switch_every_s,
                  "Pin another configuration every this many seconds over the control socket, "
                  "in turn primary 2, spacing 3, 600 Hz and primary 3, spacing 2, 1000 Hz (as "
                  "`hapticsim ctl pin` does): the daemon switches them in contact too, carrying "
                  "the object's motion; checks every pin but the last switched. 0: never")
      ->check(CLI::NonNegativeNumber);
  app->add_option("--deformation-rate", options->deformation_rate_hz,
                  "The daemon's deformed-surface frames per second ([deformation] rate_hz, Hz; "
                  "0: none), received on LCM as a viewer would")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 240.0));
  app->add_flag("--json", options->json, "Print the summary as JSON");
  return {app, [options, argc, argv] {
            if (!std::getenv(kInNetnsVariable)) ReexecInPrivateNetns(argc, argv);
            return RunSoak(*options);
          }};
}

}  // namespace hapticsim::cli
