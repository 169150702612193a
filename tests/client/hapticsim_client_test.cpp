// The C API's own contract (client/hapticsim_client.h): what a C caller gets for bad arguments
// and for a socket with no daemon. A real daemon driven through it: tests/packaging/
// install_test.sh (the installed library, from C, C++ and Python).
#include "hapticsim_client.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <string>

#include "tests/support/private_socket.hpp"

namespace {

TEST(ClientCApi, NoDaemonAtTheSocketIsAClearReasonAndNoClient) {
  const std::string socket = hapticsim::testing::PrivateSocketPath();
  char why[512];
  std::memset(why, 'x', sizeof why);
  EXPECT_EQ(hapticsim_connect(socket.c_str(), why, sizeof why), nullptr);
  const std::string reason = why;
  EXPECT_NE(reason.find(socket), std::string::npos) << reason;  // says where it looked

  // A short buffer gets the reason's beginning, terminated; none at all is allowed.
  char short_why[8];
  EXPECT_EQ(hapticsim_connect(socket.c_str(), short_why, sizeof short_why), nullptr);
  EXPECT_EQ(std::strlen(short_why), sizeof short_why - 1);
  EXPECT_EQ(std::string(short_why), reason.substr(0, sizeof short_why - 1));
  EXPECT_EQ(hapticsim_connect(socket.c_str(), nullptr, 0), nullptr);
}

TEST(ClientCApi, EveryCallTakesANullClientWithoutHarm) {
  const double position[3] = {0, 0, 0};
  hapticsim_force force;
  hapticsim_status status;
  EXPECT_EQ(hapticsim_send_pose(nullptr, 1, 0, position), -1);
  EXPECT_EQ(hapticsim_read_force(nullptr, &force), -1);
  EXPECT_EQ(hapticsim_read_status(nullptr, &status), -1);
  EXPECT_EQ(hapticsim_is_live(nullptr, 0), 0);
  EXPECT_EQ(hapticsim_reconnect(nullptr), 0);
  hapticsim_disconnect(nullptr);
}

TEST(ClientCApi, SaysItsVersion) {
  const std::string version = hapticsim_client_version();
  EXPECT_EQ(std::count(version.begin(), version.end(), '.'), 2) << version;
}

}  // namespace
