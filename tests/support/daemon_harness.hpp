#pragma once

// What the daemon's end-to-end and security tests share: a real hapticsimd started beside the
// test, and a real LCM client of it. LCM needs the private network namespace the tests run in
// (tests/support/in_private_netns.sh).

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <fstream>
#include <cstdint>
#include <functional>
#include <lcm/lcm-cpp.hpp>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "hapticsim/command_t.hpp"
#include "ipc/command_signature.hpp"
#include "hapticsim/device_input_t.hpp"
#include "hapticsim/force_feedback_t.hpp"
#include "hapticsim/status_t.hpp"
#include "tests/support/run_command.hpp"

namespace hapticsim::testing {

using HarnessClock = std::chrono::steady_clock;

// Waits until the daemon logs that it serves (startup estimates stability first), at most 30 s.
inline void WaitUntilServing(BackgroundProcess& daemon) {
  const auto deadline = HarnessClock::now() + std::chrono::seconds(30);
  while (daemon.Log().find("serving") == std::string::npos && HarnessClock::now() < deadline) {
    ASSERT_TRUE(daemon.running()) << daemon.Log();
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

// How many threads process `pid` has now (-1: it is gone).
inline int ThreadsOf(int pid) {
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  for (std::string line; std::getline(status, line);) {
    if (line.rfind("Threads:", 0) == 0) return std::stoi(line.substr(8));
  }
  return -1;
}

// The client side: what a device driver and a monitoring tool see.
class Client {
 public:
  Client() : lcm_("udpm://239.255.76.67:7667?ttl=0") {
    EXPECT_TRUE(lcm_.good()) << "no LCM: is this running inside tests/support/in_private_netns.sh?";
    lcm_.subscribe("HAPTIC_FORCE", &Client::OnForce, this);
    lcm_.subscribe("HAPTIC_STATUS", &Client::OnStatus, this);
    thread_ = std::thread([this] {
      while (!stop_) lcm_.handleTimeout(10);
    });
  }
  ~Client() {
    stop_ = true;
    thread_.join();
  }

  void Send(std::int64_t seq, double x, double y, double z) {
    device_input_t input{};
    input.utime = seq;
    input.seq = seq;
    input.position[0] = x, input.position[1] = y, input.position[2] = z;
    lcm_.publish("HAPTIC_DEVICE", &input);
  }
  void SendRaw(const std::string& bytes) {
    lcm_.publish("HAPTIC_DEVICE", bytes.data(), static_cast<unsigned>(bytes.size()));
  }
  /** Sends `command` as it is (signed or not). */
  void Command(const command_t& command) { lcm_.publish("HAPTIC_COMMAND", &command); }
  /** Stamps `command` with the wall clock and signs it with `key`, as hapticsim ctl --lcm does. */
  void SignedCommand(command_t command, const CommandKey& key) {
    command.utime = CommandClockUs();
    SignCommand(&command, "HAPTIC_COMMAND", key);
    Command(command);
  }

  std::vector<force_feedback_t> Forces() {
    std::lock_guard lock(mutex_);
    return forces_;
  }
  std::optional<status_t> LastStatus() {
    std::lock_guard lock(mutex_);
    return status_;
  }
  // Waits until `predicate(last status)` holds.
  bool WaitForStatus(const std::function<bool(const status_t&)>& predicate, double timeout_s) {
    const auto end = HarnessClock::now() + std::chrono::duration<double>(timeout_s);
    while (HarnessClock::now() < end) {
      if (auto s = LastStatus(); s && predicate(*s)) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return false;
  }

 private:
  void OnForce(const lcm::ReceiveBuffer*, const std::string&, const force_feedback_t* f) {
    std::lock_guard lock(mutex_);
    forces_.push_back(*f);
  }
  void OnStatus(const lcm::ReceiveBuffer*, const std::string&, const status_t* s) {
    std::lock_guard lock(mutex_);
    status_ = *s;
  }

  lcm::LCM lcm_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
  std::mutex mutex_;
  std::vector<force_feedback_t> forces_;
  std::optional<status_t> status_;
};

}  // namespace hapticsim::testing
