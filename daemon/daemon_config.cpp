#include "daemon/daemon_config.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <map>
#include <optional>
#include <sstream>
#include <type_traits>

#include "core/error.hpp"
#include "core/regions/proxy_following.hpp"
#include "core/scene/scene_toml.hpp"
#include "daemon/contact_object.hpp"
#include "daemon/supervisor.hpp"

namespace hapticsim {
namespace {

using Setter = std::function<void(DaemonConfig*, const toml::node&, const std::string& where)>;

template <typename T>
T Get(const toml::node& node, const std::string& key, const std::string& where, const char* type) {
  // A flag must be true or false as written: toml++'s value<bool>() would take 3 or 0 as well.
  // A whole number must be written as one: value<int64_t>() would cast a float, and one beyond
  // the range of int64 (1e103) is undefined behaviour.
  std::optional<T> value;
  if constexpr (std::is_same_v<T, bool> || std::is_integral_v<T>) {
    value = node.value_exact<T>();
  } else {
    value = node.value<T>();
  }
  if (!value) throw Error(where + ": " + key + " must be " + type);
  return *value;
}

// A whole number for an int field: one beyond int's range becomes -1, which every such field's
// validation refuses, instead of wrapping round into its range (2³² + 10 would read as 10).
int SmallInt(std::int64_t value) {
  return value >= std::numeric_limits<int>::min() && value <= std::numeric_limits<int>::max()
             ? static_cast<int>(value)
             : -1;
}

using SetterMap = std::map<std::string, Setter>;

void Text(SetterMap& s, const std::string& key, std::string DaemonConfig::*field) {
  s[key] = [key, field](DaemonConfig* c, const toml::node& n, const std::string& where) {
    c->*field = Get<std::string>(n, key, where, "a string");
  };
}
void Real(SetterMap& s, const std::string& key, double DaemonConfig::*field) {
  s[key] = [key, field](DaemonConfig* c, const toml::node& n, const std::string& where) {
    c->*field = Get<double>(n, key, where, "a number");
  };
}
void Flag(SetterMap& s, const std::string& key, bool DaemonConfig::*field) {
  s[key] = [key, field](DaemonConfig* c, const toml::node& n, const std::string& where) {
    c->*field = Get<bool>(n, key, where, "true or false");
  };
}

// [device] and [realtime]: the force envelope and the region threads.
void AddDeviceAndRealtimeKeys(SetterMap& s) {
  Text(s, "device.input", &DaemonConfig::device_input);
  auto port = [&s](const std::string& key, double PortGuardSettings::*field) {
    s[key] = [key, field](DaemonConfig* c, const toml::node& n, const std::string& where) {
      c->port.*field = Get<double>(n, key, where, "a number");
    };
  };
  port("device.max_force_n", &PortGuardSettings::max_force_n);
  port("device.max_force_rate_n_per_ms", &PortGuardSettings::max_force_rate_n_per_ms);
  port("device.engage_rate_n_per_ms", &PortGuardSettings::engage_rate_n_per_ms);
  port("device.lift_off_rate_n_per_ms", &PortGuardSettings::lift_off_rate_n_per_ms);
  port("device.fault_force_n", &PortGuardSettings::fault_force_n);
  port("device.watchdog_s", &PortGuardSettings::watchdog_s);
  port("device.max_damping_n_s_per_m", &PortGuardSettings::max_damping_n_s_per_m);
  s["device.passivity"] = [](DaemonConfig* c, const toml::node& n, const std::string& where) {
    c->port.passivity = Get<bool>(n, "device.passivity", where, "true or false");
  };
  s["realtime.fifo_priority"] = [](DaemonConfig* c, const toml::node& n, const std::string& w) {
    c->fifo_priority =
        SmallInt(Get<std::int64_t>(n, "realtime.fifo_priority", w, "a whole number"));
  };
  s["realtime.cpus"] = [](DaemonConfig* c, const toml::node& n, const std::string& where) {
    const toml::array* list = n.as_array();
    if (!list) throw Error(where + ": realtime.cpus must be a list of CPU numbers, e.g. [1]");
    c->cpus.clear();
    for (const toml::node& cpu : *list) {
      c->cpus.push_back(SmallInt(Get<std::int64_t>(cpu, "realtime.cpus", where, "whole numbers")));
    }
  };
  Flag(s, "realtime.lock_memory", &DaemonConfig::lock_memory);
  Flag(s, "realtime.sleep_at_rest", &DaemonConfig::sleep_at_rest);
}

const SetterMap& Setters() {
  static const SetterMap setters = [] {
    SetterMap s;
    Text(s, "scene.file", &DaemonConfig::scene_file);
    Flag(s, "lcm.enabled", &DaemonConfig::lcm_enabled);
    Text(s, "lcm.url", &DaemonConfig::lcm_url);
    Flag(s, "lcm.allow_network", &DaemonConfig::lcm_allow_network);
    Text(s, "lcm.device_channel", &DaemonConfig::device_channel);
    Text(s, "lcm.force_channel", &DaemonConfig::force_channel);
    Text(s, "lcm.status_channel", &DaemonConfig::status_channel);
    Text(s, "lcm.command_channel", &DaemonConfig::command_channel);
    Text(s, "lcm.deformation_channel", &DaemonConfig::deformation_channel);
    Flag(s, "lcm.accept_commands", &DaemonConfig::lcm_accept_commands);
    Text(s, "lcm.command_key_file", &DaemonConfig::lcm_command_key_file);
    Flag(s, "control.enabled", &DaemonConfig::control_enabled);
    Text(s, "control.socket", &DaemonConfig::control_socket);
    Text(s, "control.group", &DaemonConfig::control_group);
    Flag(s, "shm.enabled", &DaemonConfig::shm_enabled);
    Text(s, "shm.socket", &DaemonConfig::shm_socket);
    s["shm.name"] = [](DaemonConfig*, const toml::node&, const std::string& where) {
      throw Error(where +
                  ": shm.name is gone: the segment has no name any more (no other process can "
                  "open or replace it). Drivers connect to shm.socket, a Unix socket path "
                  "(default /run/hapticsim/hapticsimd.sock), and get the segment from it");
    };
    Text(s, "shm.group", &DaemonConfig::shm_group);
    Text(s, "supervisor.error_map", &DaemonConfig::error_map);
    Real(s, "supervisor.error_target_percent", &DaemonConfig::error_target_percent);
    Real(s, "supervisor.status_rate_hz", &DaemonConfig::status_rate_hz);
    Real(s, "input.stale_after_s", &DaemonConfig::stale_after_s);
    Flag(s, "input.zero_force_when_stale", &DaemonConfig::zero_force_when_stale);
    Real(s, "input.max_speed_m_per_s", &DaemonConfig::max_speed_m_per_s);
    Real(s, "input.workspace_margin_m", &DaemonConfig::workspace_margin_m);
    s["input.max_force_n"] = [](DaemonConfig*, const toml::node&, const std::string& where) {
      throw Error(where +
                  ": input.max_force_n moved to [device] max_force_n, the device's force "
                  "ceiling (desktop devices: 8 N; a force above device.fault_force_n is a fault)");
    };
    AddDeviceAndRealtimeKeys(s);
    Real(s, "deformation.rate_hz", &DaemonConfig::deformation_rate_hz);
    Text(s, "log.level", &DaemonConfig::log_level);
    Real(s, "log.max_lines_per_s", &DaemonConfig::max_log_lines_per_s);
    return s;
  }();
  return setters;
}

// The adaptive configuration the daemon starts from (before the supervisor chooses one) is
// given by the scene file's [adaptivity]; without one, the scene's default spacing factor at
// the default primary size, with the secondary at the primary rate: equal rates are exactly
// monolithic, so a daemon without a map starts from a configuration whose coupling is stable by
// construction. The other adaptivity settings (shells, outer_rate, …) stay the scene's.
void DefaultAdaptivity(Scene* scene) {
  if (scene->adaptivity.primary_size > 0) return;
  scene->adaptivity.primary_size = RegionConfiguration::kDaemonPrimarySize;
  scene->adaptivity.secondary_rate_hz = PrimaryRateHz(*scene);
}

// [device]'s force envelope: ceilings a hand and a desk set.
void ValidatePortGuard(const PortGuardSettings& p) {
  auto require = [](bool ok, const std::string& message) {
    if (!ok) throw Error(message);
  };
  auto value = [](double v) { return " (it is " + FormatReal(v) + ")"; };
  require(std::isfinite(p.max_force_n) && p.max_force_n > 0 && p.max_force_n <= 100,
          "device.max_force_n must be in (0, 100] N; desktop devices are rated 3–9 N peak" +
              value(p.max_force_n));
  // A release from the ceiling to zero within a second: a fault must not hold force for longer.
  require(std::isfinite(p.max_force_rate_n_per_ms) &&
              p.max_force_rate_n_per_ms >= p.max_force_n / 1000 && p.max_force_rate_n_per_ms <= 100,
          "device.max_force_rate_n_per_ms must be from device.max_force_n / 1000 ms (" +
              FormatReal(p.max_force_n / 1000) + ") to 100 N per ms" +
              value(p.max_force_rate_n_per_ms));
  require(std::isfinite(p.engage_rate_n_per_ms) && p.engage_rate_n_per_ms >= p.max_force_n / 1000 &&
              p.engage_rate_n_per_ms <= p.max_force_rate_n_per_ms,
          "device.engage_rate_n_per_ms must be from device.max_force_n / 1000 ms (" +
              FormatReal(p.max_force_n / 1000) + ") to device.max_force_rate_n_per_ms (" +
              FormatReal(p.max_force_rate_n_per_ms) + ") N per ms" + value(p.engage_rate_n_per_ms));
  // (Above the slew ceiling it is that ceiling: a profile with a slew below the default 0.1 loads
  // as it did before the key came.)
  require(std::isfinite(p.lift_off_rate_n_per_ms) &&
              p.lift_off_rate_n_per_ms >= p.max_force_n / 1000 && p.lift_off_rate_n_per_ms <= 100,
          "device.lift_off_rate_n_per_ms must be from device.max_force_n / 1000 ms (" +
              FormatReal(p.max_force_n / 1000) + ") to 100 N per ms" +
              value(p.lift_off_rate_n_per_ms));
  require(
      std::isfinite(p.fault_force_n) && p.fault_force_n >= p.max_force_n && p.fault_force_n <= 1000,
      "device.fault_force_n must be from device.max_force_n (" + FormatReal(p.max_force_n) +
          ") to 1000 N" + value(p.fault_force_n));
  require(std::isfinite(p.watchdog_s) && p.watchdog_s >= 0.05 && p.watchdog_s <= 10,
          "device.watchdog_s must be from 0.05 to 10 s (a loaded desktop stalls a process for "
          "up to 0.1 s)" +
              value(p.watchdog_s));
  require(
      std::isfinite(p.max_damping_n_s_per_m) && p.max_damping_n_s_per_m >= 0 &&
          p.max_damping_n_s_per_m <= 1000,
      "device.max_damping_n_s_per_m must be from 0 to 1000 N·s/m" + value(p.max_damping_n_s_per_m));
}

}  // namespace

void ValidateDaemonConfig(const DaemonConfig& c) {
  auto require = [](bool ok, const std::string& message) {
    if (!ok) throw Error(message);
  };
  require(std::isfinite(c.error_target_percent) && c.error_target_percent > 0 &&
              c.error_target_percent <= 100,
          "supervisor.error_target_percent must be in (0, 100] %");
  require(std::isfinite(c.status_rate_hz) && c.status_rate_hz >= 0.1 && c.status_rate_hz <= 100,
          "supervisor.status_rate_hz must be from 0.1 to 100 Hz");
  require(std::isfinite(c.stale_after_s) && c.stale_after_s >= 0.002 && c.stale_after_s <= 10,
          "input.stale_after_s must be from 0.002 to 10 s");
  // Ceilings a hand and a desk set: a limit of 1e300 checks nothing.
  require(
      std::isfinite(c.max_speed_m_per_s) && c.max_speed_m_per_s > 0 && c.max_speed_m_per_s <= 100,
      "input.max_speed_m_per_s must be in (0, 100] m/s; a hand moves at most a few m/s");
  require(std::isfinite(c.workspace_margin_m) && c.workspace_margin_m >= 0 &&
              c.workspace_margin_m <= 10,
          "input.workspace_margin_m must be from 0 to 10 m");
  ValidatePortGuard(c.port);
  require(c.device_input.empty() || c.device_input == "lcm" || c.device_input == "shm",
          "device.input must be \"lcm\" or \"shm\" (it is \"" + c.device_input + "\")");
  require(c.device_input != "shm" || c.shm_enabled,
          "device.input = \"shm\" needs shm.enabled = true");
  require(c.device_input != "lcm" || c.lcm_enabled,
          "device.input = \"lcm\" needs lcm.enabled = true");
  require(
      c.deformation_rate_hz == 0 || (c.deformation_rate_hz >= 1 && c.deformation_rate_hz <= 240),
      "deformation.rate_hz must be 0 (off) or from 1 to 240 frames per second (a display's "
      "rate)");
  require(c.fifo_priority >= 0 && c.fifo_priority <= 99,
          "realtime.fifo_priority must be from 0 (off) to 99");
  for (int cpu : c.cpus) require(cpu >= 0 && cpu < 4096, "realtime.cpus: CPU numbers are >= 0");
  require(std::isfinite(c.max_log_lines_per_s) && c.max_log_lines_per_s > 0 &&
              c.max_log_lines_per_s <= 1000,
          "log.max_lines_per_s must be in (0, 1000]: more would let a flood of bad input flood "
          "the journal");
  const std::vector<std::string> levels = {"trace", "debug", "info", "warn", "error"};
  require(std::find(levels.begin(), levels.end(), c.log_level) != levels.end(),
          "log.level must be one of trace, debug, info, warn, error");
  for (const auto& [key, channel] : {std::pair{"lcm.device_channel", &c.device_channel},
                                     {"lcm.force_channel", &c.force_channel},
                                     {"lcm.status_channel", &c.status_channel},
                                     {"lcm.command_channel", &c.command_channel},
                                     {"lcm.deformation_channel", &c.deformation_channel}}) {
    require(!channel->empty() && channel->size() <= 63,
            std::string(key) + " must be a channel name of 1 to 63 characters");
  }
  for (const auto& [key, path] :
       {std::pair{"shm.socket", &c.shm_socket}, {"control.socket", &c.control_socket}}) {
    require(path->size() > 1 && (*path)[0] == '/' && path->back() != '/' && path->size() <= 107,
            std::string(key) +
                " must be an absolute path of a socket file, at most 107 bytes (a Unix "
                "socket's limit), e.g. \"/run/hapticsim/hapticsimd.sock\"");
  }
  require(!(c.lcm_enabled && c.lcm_accept_commands) || !c.lcm_command_key_file.empty(),
          "lcm.accept_commands = true needs lcm.command_key_file: commands on LCM are taken only "
          "when signed with a key the sender shares (make one with `hapticsim ctl --make-key "
          "FILE`), or use hapticsim ctl over the control socket instead");
  require(c.lcm_command_key_file.empty() || c.lcm_command_key_file[0] == '/',
          "lcm.command_key_file must be an absolute path");
  require(!(c.shm_enabled && c.control_enabled && c.shm_socket == c.control_socket),
          "shm.socket and control.socket must be different files");
  const std::string url_problem = LcmUrlProblem(c.lcm_url, c.lcm_allow_network);
  require(url_problem.empty(), url_problem);
  require(c.scene.adaptivity.enabled(),
          "the scene's adaptivity.primary_size must be >= 1 (the daemon runs regions)");
  ValidateScene(c.scene);
  // The object as the loop will meet it: its geometry read, its supports checked to hold it, a
  // surface node left for the tool (each throws saying what to fix).
  const ContactObject object = ContactObject::Of(c.scene);
  // A sliding tool's primary follows its proxy and must reach every node its tip touches.
  if (UsesProxyContact(c.scene)) {
    CheckPrimaryReachesTip(c.scene, object.spacing_m(), kThreadsFollowSlack);
  }
}

std::string LcmUrlProblem(const std::string& url, bool allow_network) {
  const size_t scheme_end = url.find("://");
  if (scheme_end == std::string::npos || scheme_end == 0) {
    return "lcm.url must look like udpm://239.255.76.67:7667?ttl=0 or memq:// (it is \"" + url +
           "\")";
  }
  const std::string scheme = url.substr(0, scheme_end), rest = url.substr(scheme_end + 3);
  const std::string allow =
      ": keep it on this host, or set lcm.allow_network = true on a network you trust";
  if (scheme == "memq" || scheme == "file") return "";
  if (scheme == "udpm" || scheme == "mpudpm") {
    std::optional<std::string> ttl;
    const size_t query = rest.find('?');
    for (size_t at = query; at != std::string::npos && at + 1 < rest.size();) {
      const size_t end = rest.find('&', at + 1);
      const std::string option = rest.substr(at + 1, end == std::string::npos ? end : end - at - 1);
      if (option.rfind("ttl=", 0) == 0) ttl = option.substr(4);
      at = end;
    }
    if (!ttl) return "";  // LCM's own default: ttl=0
    const bool whole =
        !ttl->empty() && ttl->size() <= 3 &&
        std::all_of(ttl->begin(), ttl->end(), [](char d) { return d >= '0' && d <= '9'; });
    if (!whole || std::stoi(*ttl) > 255) {
      return "lcm.url: ttl must be a whole number from 0 to 255 (it is '" + *ttl + "')";
    }
    if (std::stoi(*ttl) > 0 && !allow_network) {
      return "lcm.url: ttl=" + *ttl + " sends LCM traffic off this host" + allow;
    }
    return "";
  }
  if (scheme == "tcpq") {
    const std::string host = rest.substr(0, rest.find_first_of(":/"));
    in_addr address{};  // an address in 127.0.0.0/8, parsed, not a name that starts "127."
    const bool loopback = host == "localhost" || (inet_pton(AF_INET, host.c_str(), &address) == 1 &&
                                                  (ntohl(address.s_addr) >> 24) == 127);
    if (!loopback && !allow_network)
      return "lcm.url: " + url + " sends LCM traffic off this host" + allow;
    return "";
  }
  return "lcm.url: unknown LCM provider '" + scheme + "' (udpm, mpudpm, tcpq, memq or file)";
}

bool LcmUrlLeavesHost(const std::string& url) {
  return !LcmUrlProblem(url, false).empty() && LcmUrlProblem(url, true).empty();
}

std::string DeviceInputOf(const DaemonConfig& config) {
  if (!config.device_input.empty()) return config.device_input;
  return config.shm_enabled ? "shm" : "lcm";
}

const char* DeviceInputName(const DaemonConfig& config, bool other) {
  return (DeviceInputOf(config) == "shm") != other ? "shared memory" : "LCM";
}

DaemonConfig DefaultDaemonConfig() {
  DaemonConfig config;
  DefaultAdaptivity(&config.scene);
  return config;
}

namespace {

DaemonConfig ParseDaemonConfig(const std::string& path, const std::optional<std::string>& text,
                               bool read_scene_file) {
  toml::table document;
  try {
    document = text ? toml::parse(*text, path) : toml::parse_file(path);
  } catch (const toml::parse_error& e) {
    if (e.source().begin.line == 0) {
      throw Error("cannot read config file " + path + ": " + std::string(e.description()));
    }
    throw Error("config file " + path + ":" + std::to_string(e.source().begin.line) + ": " +
                std::string(e.description()));
  }
  DaemonConfig config;
  for (const auto& [section, node] : document) {
    const toml::table* table = node.as_table();
    std::string where = "config file ";
    where.append(path).append(":").append(std::to_string(node.source().begin.line));
    if (!table) throw Error(where + ": '" + std::string(section.str()) + "' must be a [section]");
    for (const auto& [key, value] : *table) {
      const std::string name = std::string(section.str()) + "." + std::string(key.str());
      std::string at = "config file ";
      at.append(path).append(":").append(std::to_string(value.source().begin.line));
      const auto setter = Setters().find(name);
      if (setter == Setters().end()) {
        std::string known;
        for (const auto& entry : Setters()) known.append(" ").append(entry.first);
        throw Error(at + ": unknown key " + name + "; keys are" + known);
      }
      setter->second(&config, value, at);
    }
  }
  if (!config.scene_file.empty() && !read_scene_file) {
    throw Error("config file " + path + ": scene.file is not read here");
  }
  config.scene = config.scene_file.empty() ? Scene{} : LoadSceneFile(config.scene_file);
  DefaultAdaptivity(&config.scene);
  try {
    ValidateDaemonConfig(config);
  } catch (const Error& e) {
    throw Error("config file " + path + ": " + e.what());
  }
  return config;
}

}  // namespace

DaemonConfig LoadDaemonConfig(const std::string& path) { return ParseDaemonConfig(path, {}, true); }

DaemonConfig ParseDaemonConfigText(const std::string& text, const std::string& origin,
                                   bool read_scene_file) {
  return ParseDaemonConfig(origin, text, read_scene_file);
}

namespace {

// A TOML basic string: backslashes, quotes and control characters escaped, so that what is
// printed reads back as the same text (found by fuzzing a URL with backslashes in it).
std::string TomlString(const std::string& s) {
  std::string out = "\"";
  for (const char ch : s) {
    const auto byte = static_cast<unsigned char>(ch);
    if (ch == '\\' || ch == '"') {
      out += '\\';
      out += ch;
    } else if (byte < 0x20 || byte == 0x7f) {
      char escaped[8];
      std::snprintf(escaped, sizeof escaped, "\\u%04X", byte);
      out += escaped;
    } else {
      out += ch;
    }
  }
  return out + "\"";
}

}  // namespace

std::string FormatDaemonConfig(const DaemonConfig& c) {
  std::ostringstream out;
  const auto quote = TomlString;
  auto real = [](double v) { return FormatReal(v); };
  out << "# hapticsimd configuration (every key optional; these are the values in effect)\n"
      << "[scene]\nfile = " << quote(c.scene_file) << "\n\n"
      << "[lcm]\nenabled = " << (c.lcm_enabled ? "true" : "false") << "\n"
      << "url = " << quote(c.lcm_url) << "  # ttl=0: multicast stays on this host\n"
      << "allow_network = " << (c.lcm_allow_network ? "true" : "false")
      << "  # true lets url send traffic off this host (ttl > 0, tcpq:// to another machine)\n"
      << "device_channel = " << quote(c.device_channel) << "\n"
      << "force_channel = " << quote(c.force_channel) << "\n"
      << "status_channel = " << quote(c.status_channel) << "\n"
      << "command_channel = " << quote(c.command_channel) << "\n"
      << "deformation_channel = " << quote(c.deformation_channel)
      << "  # the deformed surface (deformation_t), at [deformation] rate_hz\n"
      << "accept_commands = " << (c.lcm_accept_commands ? "true" : "false")
      << "  # commands come from hapticsim ctl ([control]); true: signed LCM commands too\n"
      << "command_key_file = " << quote(c.lcm_command_key_file)
      << "  # the key signed LCM commands share (hapticsim ctl --make-key FILE)\n\n"
      << "[control]  # hapticsim ctl: reset, pin, release, set-error-target\n"
      << "enabled = " << (c.control_enabled ? "true" : "false") << "\n"
      << "socket = " << quote(c.control_socket) << "\n"
      << "group = " << quote(c.control_group)
      << "  # who may send commands besides root and the daemon's user\n\n"
      << "[shm]\nenabled = " << (c.shm_enabled ? "true" : "false") << "\n"
      << "socket = " << quote(c.shm_socket)
      << "  # drivers connect here; its directory only the daemon may write\n"
      << "group = " << quote(c.shm_group) << "  # the driver's group; socket mode 0660\n\n"
      << "[supervisor]\nerror_map = " << quote(c.error_map) << "\n"
      << "error_target_percent = " << real(c.error_target_percent) << "\n"
      << "status_rate_hz = " << real(c.status_rate_hz) << "\n\n"
      << "[input]\nstale_after_s = " << real(c.stale_after_s) << "\n"
      << "zero_force_when_stale = " << (c.zero_force_when_stale ? "true" : "false") << "\n"
      << "max_speed_m_per_s = " << real(c.max_speed_m_per_s) << "\n"
      << "workspace_margin_m = " << real(c.workspace_margin_m) << "\n\n"
      << "[device]  # the driver's transport and the force envelope (docs/operations.md)\n"
      // Unset, the input follows [shm] enabled: written as a comment, so that a config made from
      // this output (the installed default) still does.
      << (c.device_input.empty()
              ? "# input: unset, so shared memory's when [shm] enabled = true, else LCM's (now \"" +
                    DeviceInputOf(c) + "\")\n"
              : "input = " + quote(c.device_input) +
                    "  # \"lcm\" or \"shm\": the other is refused\n")
      << "max_force_n = " << real(c.port.max_force_n) << "\n"
      << "max_force_rate_n_per_ms = " << real(c.port.max_force_rate_n_per_ms) << "\n"
      << "engage_rate_n_per_ms = " << real(c.port.engage_rate_n_per_ms) << "\n"
      << "lift_off_rate_n_per_ms = " << real(c.port.lift_off_rate_n_per_ms)
      << "  # a lift-off's release (the engage ramp's if faster; at most the slew)\n"
      << "fault_force_n = " << real(c.port.fault_force_n) << "\n"
      << "watchdog_s = " << real(c.port.watchdog_s) << "\n"
      << "passivity = " << (c.port.passivity ? "true" : "false") << "\n"
      << "max_damping_n_s_per_m = " << real(c.port.max_damping_n_s_per_m) << "\n\n"
      << "[realtime]\nfifo_priority = " << c.fifo_priority << "\ncpus = [";
  for (size_t i = 0; i < c.cpus.size(); ++i) out << (i ? ", " : "") << c.cpus[i];
  out << "]\nlock_memory = " << (c.lock_memory ? "true" : "false") << "\n"
      << "sleep_at_rest = " << (c.sleep_at_rest ? "true" : "false")
      << "  # untouched and at rest: regions not stepped, ~0 CPU\n\n"
      << "[deformation]  # the deformed surface out: deformation_t on LCM, and in shared memory\n"
      << "rate_hz = " << real(c.deformation_rate_hz) << "  # frames per second, 0: none\n\n"
      << "[log]\nlevel = " << quote(c.log_level) << "\n"
      << "max_lines_per_s = " << real(c.max_log_lines_per_s) << "\n";
  return out.str();
}

}  // namespace hapticsim
