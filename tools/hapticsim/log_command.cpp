// hapticsim log: what a recorded session (lcm-logger) holds — channels, rates, force and error
// statistics, gaps — and its device inputs and forces as CSV.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <lcm/lcm-cpp.hpp>
#include <map>
#include <nlohmann/json.hpp>

#include "core/error.hpp"
#include "hapticsim/device_input_t.hpp"
#include "hapticsim/force_feedback_t.hpp"
#include "tools/hapticsim/command.hpp"
#include "tools/hapticsim/device_report.hpp"

namespace hapticsim::cli {
namespace {

struct LogOptions {
  std::string path;
  std::string csv;
  std::string device_channel = "HAPTIC_DEVICE", force_channel = "HAPTIC_FORCE";
  double gap_ms = 5;
  bool json = false;
};

struct ChannelStats {
  std::int64_t messages = 0, bytes = 0, gaps = 0;
  std::int64_t first_us = -1, last_us = -1;
  double longest_gap_ms = 0;
};

struct RunningStats {
  std::int64_t n = 0;
  double sum = 0, min = INFINITY, max = -INFINITY;
  void Add(double v) { ++n, sum += v, min = std::min(min, v), max = std::max(max, v); }
  nlohmann::json Json() const {
    if (n == 0) return nullptr;
    return {{"mean", sum / n}, {"min", min}, {"max", max}, {"count", n}};
  }
};

int Run(const LogOptions& o) {
  lcm::LogFile log(o.path, "r");
  HAPTICSIM_THROW_UNLESS(log.good(), o.path + ": cannot open it as an LCM log (lcm-logger)");
  std::ofstream csv;
  if (!o.csv.empty()) {
    csv.open(o.csv);
    HAPTICSIM_THROW_UNLESS(csv.good(), "--csv " + o.csv + ": cannot write it");
    csv << "time_s,channel,seq,period,x_m,y_m,z_m,force_x_N,force_y_N,force_z_N,error_percent,"
           "flags\n";
    csv.precision(9);
  }
  std::map<std::string, ChannelStats> channels;
  RunningStats force_n, error_percent;
  std::int64_t undecodable = 0, device_seq_gaps = 0, force_period_gaps = 0, contact = 0;
  std::int64_t last_seq = -1, last_period = -1, first_us = -1, last_us = -1, forces = 0;
  std::int32_t flags_seen = 0;
  while (const lcm::LogEvent* event = log.readNextEvent()) {
    if (first_us < 0) first_us = event->timestamp;
    last_us = event->timestamp;
    ChannelStats& c = channels[event->channel];
    if (c.last_us >= 0) {
      const double gap_ms = (event->timestamp - c.last_us) * 1e-3;
      c.longest_gap_ms = std::max(c.longest_gap_ms, gap_ms);
      // A gap: longer than --gap-ms and than 3 of the channel's mean intervals so far (a 5 Hz
      // status channel is not gapped every message).
      const double mean_ms =
          c.messages > 1 ? (c.last_us - c.first_us) * 1e-3 / (c.messages - 1) : 0.0;
      if (c.messages > 1 && gap_ms > o.gap_ms && gap_ms > 3 * mean_ms) ++c.gaps;
    }
    if (c.first_us < 0) c.first_us = event->timestamp;
    c.last_us = event->timestamp;
    ++c.messages;
    c.bytes += event->datalen;
    const double t = (event->timestamp - first_us) * 1e-6;
    if (event->channel == o.device_channel) {
      device_input_t in;
      if (in.decode(event->data, 0, event->datalen) < 0) {
        ++undecodable;
        continue;
      }
      if (last_seq >= 0 && in.seq > last_seq + 1) ++device_seq_gaps;
      last_seq = in.seq;
      if (csv.is_open()) {
        csv << t << "," << event->channel << "," << in.seq << ",," << in.position[0] << ","
            << in.position[1] << "," << in.position[2] << ",,,,,\n";
      }
    } else if (event->channel == o.force_channel) {
      force_feedback_t f;
      if (f.decode(event->data, 0, event->datalen) < 0) {
        ++undecodable;
        continue;
      }
      ++forces;
      if (last_period >= 0 && f.period > last_period + 1)
        force_period_gaps += f.period - last_period - 1;
      last_period = f.period;
      force_n.Add(std::hypot(f.force[0], f.force[1], f.force[2]));
      if (f.error_percent >= 0) error_percent.Add(f.error_percent);
      flags_seen |= f.flags;
      if (f.flags & force_feedback_t::FLAG_IN_CONTACT) ++contact;
      if (csv.is_open()) {
        csv << t << "," << event->channel << "," << f.seq << "," << f.period << ",,,," << f.force[0]
            << "," << f.force[1] << "," << f.force[2] << "," << f.error_percent << "," << f.flags
            << "\n";
      }
    }
  }
  HAPTICSIM_THROW_UNLESS(first_us >= 0, o.path + ": the log holds no messages");
  const double duration_s = (last_us - first_us) * 1e-6;
  nlohmann::json out = {{"log", o.path}, {"duration_s", duration_s}};
  nlohmann::json ch = nlohmann::json::object();
  for (const auto& [name, c] : channels) {
    const double span = (c.last_us - c.first_us) * 1e-6;
    ch[name] = {{"messages", c.messages},
                {"rate_hz", span > 0 ? (c.messages - 1) / span : 0.0},
                {"bytes", c.bytes},
                {"gaps", c.gaps},
                {"longest_gap_ms", c.longest_gap_ms}};
  }
  out["channels"] = ch;
  out["gap_threshold_ms"] = o.gap_ms;
  out["device_seq_gaps"] = device_seq_gaps;
  out["forces"] = {{"messages", forces},
                   {"lost_periods", force_period_gaps},
                   {"in_contact", contact},
                   {"magnitude_N", force_n.Json()},
                   {"error_percent", error_percent.Json()},
                   {"flags_seen", FlagNames(flags_seen)}};
  out["undecodable"] = undecodable;
  if (o.json) {
    std::cout << out.dump(2) << "\n";
  } else {
    std::printf("%s: %.3f s\n", o.path.c_str(), duration_s);
    for (const auto& [name, c] : ch.items()) {
      std::printf("  %-16s %8lld messages, %8.1f Hz, %lld gaps > %g ms (longest %.1f ms)\n",
                  name.c_str(), static_cast<long long>(c["messages"].get<std::int64_t>()),
                  c["rate_hz"].get<double>(), static_cast<long long>(c["gaps"].get<std::int64_t>()),
                  o.gap_ms, c["longest_gap_ms"].get<double>());
    }
    std::printf("  device inputs: %lld seq gaps\n", static_cast<long long>(device_seq_gaps));
    if (forces > 0) {
      std::printf(
          "  forces: %lld (%lld periods missing), %lld in contact; |F| mean %.4f N, max "
          "%.4f N\n",
          static_cast<long long>(forces), static_cast<long long>(force_period_gaps),
          static_cast<long long>(contact), force_n.sum / force_n.n, force_n.max);
      if (error_percent.n > 0) {
        std::printf("  looked-up error: %.3f … %.3f %% (mean %.3f %%)\n", error_percent.min,
                    error_percent.max, error_percent.sum / error_percent.n);
      } else {
        std::printf("  looked-up error: none (no error map)\n");
      }
      std::printf("  flags seen: %s\n", FlagNames(flags_seen).c_str());
    }
    if (undecodable)
      std::printf("  %lld messages did not decode\n", static_cast<long long>(undecodable));
    if (!o.csv.empty()) std::printf("  CSV: %s\n", o.csv.c_str());
  }
  return kExitOk;
}

}  // namespace

Command AddLogCommand(CLI::App& parent) {
  auto options = std::make_shared<LogOptions>();
  CLI::App* app = parent.add_subcommand(
      "log",
      "Summarise a recorded session (an lcm-logger log): channels, rates, gaps, force and error "
      "statistics; --csv exports its device inputs and forces (replay it with "
      "`hapticsim device --input replay --replay LOG`).");
  app->add_option("LOG", options->path, "The LCM log")->required();
  app->add_option("--csv", options->csv, "Write device inputs and forces here, one row each");
  app->add_option("--gap-ms", options->gap_ms,
                  "A pause on a channel longer than this (and than 3 of its mean intervals) is a "
                  "gap, ms")
      ->capture_default_str();
  app->add_option("--device-channel", options->device_channel)->capture_default_str();
  app->add_option("--force-channel", options->force_channel)->capture_default_str();
  app->add_flag("--json", options->json, "Print the summary as JSON");
  return {app, [options] { return Run(*options); }};
}

}  // namespace hapticsim::cli
