#include "daemon/lcm_bridge.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <spdlog/spdlog.h>
#include <sys/socket.h>
#include <unistd.h>

#include "core/error.hpp"
#include "hapticsim/device_input_t.hpp"
#include "hapticsim/force_feedback_t.hpp"
#include "ipc/lcm_start.hpp"

namespace hapticsim {

std::string MulticastSourceOffLoopback(const std::string& url) {
  const std::string scheme = "udpm://";
  if (url.rfind(scheme, 0) != 0) return "";
  const std::string rest = url.substr(scheme.size());
  std::string group = rest.substr(0, rest.find_first_of(":?/"));
  if (group.empty()) group = "239.255.76.67";  // LCM's default
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_port = htons(7667);  // any port: only the route matters
  // inet_aton, as LCM reads the group (it takes forms inet_pton does not, e.g. 0xef.255.76.67).
  if (inet_aton(group.c_str(), &to.sin_addr) == 0) return "";
  const int probe = socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (probe < 0) return "";
  sockaddr_in from{};
  socklen_t length = sizeof from;
  const bool routed = connect(probe, reinterpret_cast<sockaddr*>(&to), sizeof to) == 0 &&
                      getsockname(probe, reinterpret_cast<sockaddr*>(&from), &length) == 0;
  close(probe);
  // 0.0.0.0: a route on lo without `src`: lo's address is host-scoped, so the packets leave with
  // source 0.0.0.0. Not off loopback; under the systemd unit LCM's self test then fails, and
  // LcmStartProblem says so with the route to use.
  const std::uint32_t source = ntohl(from.sin_addr.s_addr);
  if (!routed || source == INADDR_ANY || (source >> 24) == 127) return "";
  char text[INET_ADDRSTRLEN] = "";
  inet_ntop(AF_INET, &from.sin_addr, text, sizeof text);
  return text;
}

LcmBridge::LcmBridge(const DaemonConfig& config, HapticLoop& loop, InputCounters& counters,
                     std::optional<SignedCommandGate> gate)
    : config_(config),
      counters_(counters),
      lcm_(config.lcm_url),
      intake_(config.workspace_margin_m, config.max_speed_m_per_s, loop, counters,
              DeviceInputOf(config) == "lcm"),
      gate_(std::move(gate)) {
  if (const std::string problem = LcmStartProblem(lcm_, config.lcm_url); !problem.empty()) {
    throw Error(problem + " (lcm.url in the config)");
  }
  lcm_.subscribe(config.device_channel, &LcmBridge::OnDevice, this)->setQueueCapacity(1000);
  lcm_.subscribe(config.command_channel, &LcmBridge::OnCommand, this)->setQueueCapacity(100);
  LogRoute(config);
}

void LcmBridge::LogRoute(const DaemonConfig& config) {
  spdlog::info("LCM on {} (device {}, force {}, status {}, command {}, deformation {})",
               config.lcm_url, config.device_channel, config.force_channel, config.status_channel,
               config.command_channel, config.deformation_channel);
  if (const std::string source = MulticastSourceOffLoopback(config.lcm_url); !source.empty()) {
    spdlog::warn(
        "LCM's multicast group is routed off loopback (source address {}): machines on that "
        "network can send device input to the daemon, and under the systemd unit, whose IP "
        "filter admits only localhost, local LCM clients' packets (source {}) are dropped. "
        "Route the group through loopback: {}",
        source, source, kLcmLoopbackRoute);
  }
  if (LcmUrlLeavesHost(config.lcm_url)) {
    spdlog::warn(
        "LCM traffic LEAVES THIS HOST (lcm.url = {}, allowed by lcm.allow_network = true): any "
        "machine on that network can read the forces and send device input and commands",
        config.lcm_url);
  }
}

void LcmBridge::PublishDeformation(const deformation_t& frame) {
  std::lock_guard lock(publish_mutex_);
  lcm_.publish(config_.deformation_channel, &frame);
}

void LcmBridge::OnDevice(const lcm::ReceiveBuffer* buffer, const std::string&) {
  device_input_t input{};
  if (input.decode(buffer->data, 0, static_cast<int>(buffer->data_size)) < 0) {
    counters_.decode_errors.fetch_add(1);
    return;
  }
  intake_.Offer(input.seq, {input.position[0], input.position[1], input.position[2]});
}

void LcmBridge::OnCommand(const lcm::ReceiveBuffer* buffer, const std::string&) {
  command_t command{};
  if (command.decode(buffer->data, 0, static_cast<int>(buffer->data_size)) < 0) {
    counters_.decode_errors.fetch_add(1);
    return;
  }
  counters_.commands_received.fetch_add(1);
  std::string refusal = gate_ ? gate_->Refusal(command, CommandClockUs())
                              : "lcm.accept_commands is false (use hapticsim ctl)";
  std::lock_guard lock(mutex_);
  if (refusal.empty() && commands_.size() >= 100) refusal = "more than 100 commands waiting";
  if (!refusal.empty()) {
    counters_.commands_refused.fetch_add(1);
    ++refusals_.count;
    refusals_.last_reason = std::move(refusal);
    return;
  }
  commands_.push_back(command);
}

LcmBridge::Refusals LcmBridge::CommandRefusals() {
  std::lock_guard lock(mutex_);
  return refusals_;
}

void LcmBridge::Publish(const ForceRecord& record) {
  if (record.seq < 0) return;  // nothing to answer before the first input
  force_feedback_t out{};
  out.utime = record.utime_us;
  out.period = record.period;
  out.seq = record.seq;
  out.first_seq = record.first_seq;
  for (int c = 0; c < 3; ++c) out.force[c] = record.force_n[c];
  out.error_percent = record.error_percent;
  out.flags = record.flags;
  {
    std::lock_guard lock(publish_mutex_);
    lcm_.publish(config_.force_channel, &out);
  }
  counters_.forces_published.fetch_add(1);
}

void LcmBridge::PostStatus(const status_t& status) {
  std::lock_guard lock(mutex_);
  status_ = status;
}

std::optional<command_t> LcmBridge::PopCommand() {
  std::lock_guard lock(mutex_);
  if (commands_.empty()) return std::nullopt;
  command_t command = commands_.front();
  commands_.pop_front();
  return command;
}

void LcmBridge::Poll(const timespec& timeout) {
  pollfd fd{lcm_.getFileno(), POLLIN, 0};
  if (ppoll(&fd, 1, &timeout, nullptr) > 0 && (fd.revents & POLLIN)) lcm_.handle();
}

void LcmBridge::PublishPendingStatus() {
  std::optional<status_t> status;
  {
    std::lock_guard lock(mutex_);
    status.swap(status_);
  }
  if (status) {
    std::lock_guard lock(publish_mutex_);
    lcm_.publish(config_.status_channel, &*status);
  }
}

}  // namespace hapticsim
