#pragma once

// systemd's notify protocol without systemd, for tests of a real hapticsimd: the test is the
// notify socket (and, from process_threads.hpp, a thread of a running process found by name, to
// stop it alone with ptrace).
// Needs HAPTICSIMD_PATH, the daemon under test.
#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "tests/support/process_threads.hpp"
#include "tests/support/run_command.hpp"

namespace hapticsim::testing {

// systemd's side of the notify protocol, without systemd: a datagram socket the daemon is
// started against (NOTIFY_SOCKET; WATCHDOG_USEC 0.2 s, so it pings every 0.1 s), and what it said.
class FakeSystemd {
 public:
  explicit FakeSystemd(const std::string& name)
      : path_(::testing::TempDir() + "fake_systemd_" + name + ".sock") {
    std::filesystem::remove(path_);
    fd_ = socket(AF_UNIX, SOCK_DGRAM, 0);
    sockaddr_un address{};
    address.sun_family = AF_UNIX;
    std::strncpy(address.sun_path, path_.c_str(), sizeof address.sun_path - 1);
    EXPECT_EQ(bind(fd_, reinterpret_cast<sockaddr*>(&address), sizeof address), 0);
    const timeval receive_timeout{0, 100'000};
    setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &receive_timeout, sizeof receive_timeout);
  }
  ~FakeSystemd() { close(fd_); }

  std::unique_ptr<BackgroundProcess> Start(const std::string& config, const std::string& log) {
    setenv("NOTIFY_SOCKET", path_.c_str(), 1);
    setenv("WATCHDOG_USEC", "200000", 1);
    auto daemon = std::make_unique<BackgroundProcess>(
        std::vector<std::string>{HAPTICSIMD_PATH, "--config", config}, log);
    unsetenv("NOTIFY_SOCKET");
    unsetenv("WATCHDOG_USEC");
    return daemon;
  }
  // Collects messages for `seconds` (or until the first, with `until_first`).
  void ReceiveFor(double seconds, bool until_first = false) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    char buffer[256];
    while (std::chrono::steady_clock::now() < end && !(until_first && !messages.empty())) {
      const ssize_t n = recv(fd_, buffer, sizeof buffer, 0);
      if (n > 0) messages.emplace_back(buffer, static_cast<size_t>(n));
    }
  }
  long Count(const std::string& message) const {
    return static_cast<long>(std::count(messages.begin(), messages.end(), message));
  }
  std::vector<std::string> messages;

 private:
  std::string path_;
  int fd_ = -1;
};

}  // namespace hapticsim::testing
