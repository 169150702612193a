// hapticsim ctl's channel: the request words (daemon/control_line.hpp) and the control socket
// (daemon/control_server.hpp) with real Unix sockets.
#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <future>
#include <string>

#include "daemon/control_line.hpp"
#include "daemon/control_server.hpp"
#include "ipc/control_client.hpp"
#include "tests/support/private_socket.hpp"

namespace hapticsim {
namespace {

std::string ParseError(const std::string& line) {
  std::string error;
  EXPECT_FALSE(ParseControlLine(line, &error)) << line;
  return error;
}

TEST(ControlLine, EachRequestNamesItsCommandAndItsNumbers) {
  std::string error;
  auto target = ParseControlLine("set-error-target 5.5", &error);
  ASSERT_TRUE(target);
  EXPECT_EQ(target->command, command_t::SET_ERROR_TARGET);
  EXPECT_EQ(target->error_target_percent, 5.5);
  auto pin = ParseControlLine("  pin 3   2 600 ", &error);
  ASSERT_TRUE(pin);
  EXPECT_EQ(pin->command, command_t::PIN_CONFIGURATION);
  EXPECT_EQ(pin->primary_size, 3);
  EXPECT_EQ(pin->secondary_lod, 2);
  EXPECT_EQ(pin->secondary_rate_hz, 600.0);
  EXPECT_EQ(ParseControlLine("release", &error)->command, command_t::RELEASE_CONFIGURATION);
  EXPECT_EQ(ParseControlLine("reset", &error)->command, command_t::RESET);
}

TEST(ControlLine, AMalformedRequestSaysWhatIsWrongWithIt) {
  EXPECT_NE(ParseError("").find("an empty request"), std::string::npos);
  EXPECT_NE(ParseError("set-error-target").find("takes one number"), std::string::npos);
  EXPECT_NE(ParseError("set-error-target 5%").find("not a number"), std::string::npos);
  EXPECT_NE(ParseError("set-error-target nan").find("not a number"), std::string::npos);
  EXPECT_NE(ParseError("pin 3 2").find("takes three numbers"), std::string::npos);
  EXPECT_NE(ParseError("pin 3.5 2 600").find("must be whole numbers"), std::string::npos);
  EXPECT_NE(ParseError("pin 1e10 2 600").find("must be whole numbers"), std::string::npos);
  EXPECT_NE(ParseError("reset now").find("takes nothing after it"), std::string::npos);
  const std::string unknown = ParseError("RESET\x1b[2J");
  EXPECT_NE(unknown.find("unknown request \"RESET?[2J\""), std::string::npos) << unknown;
}

TEST(ControlServer, ARequestGetsItsAnswerAndASilentClientIsRefusedAfterASecond) {
  const std::string path = testing::PrivateSocketPath();
  ControlServer server(path, "");
  auto answer =
      std::async(std::launch::async, [&] { return shm::SendControlRequest(path, "reset", 5000); });
  std::optional<ControlRequest> request;
  for (int n = 0; n < 2000 && !request; ++n) {
    request = server.Next(0);
    if (!request) usleep(1000);
  }
  ASSERT_TRUE(request);
  EXPECT_EQ(request->line, "reset");
  EXPECT_EQ(request->peer.pid, getpid());
  ControlServer::Answer(*request, "ok: done");
  EXPECT_EQ(answer.get(), "ok: done");

  // A client that connects and says nothing holds nothing for long.
  const int silent = socket(AF_UNIX, SOCK_SEQPACKET, 0);
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  std::snprintf(address.sun_path, sizeof address.sun_path, "%s", path.c_str());
  ASSERT_EQ(connect(silent, reinterpret_cast<sockaddr*>(&address), sizeof address), 0);
  EXPECT_FALSE(server.Next(0));  // accepted, waiting for its request
  EXPECT_FALSE(server.Next(ControlServer::kRequestTimeout_ns + 1));
  EXPECT_EQ(server.refused(), 1);
  EXPECT_EQ(server.last_refusal(), "no request within 1 s");
  char text[64] = {};
  EXPECT_GT(recv(silent, text, sizeof text - 1, 0), 0);
  EXPECT_EQ(std::string(text), "refused: no request within 1 s");
  close(silent);
  std::filesystem::remove_all(std::filesystem::path(path).parent_path());
}

}  // namespace
}  // namespace hapticsim
