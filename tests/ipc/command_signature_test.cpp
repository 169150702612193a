// Signed LCM commands (ipc/command_signature.hpp): the MAC against a value computed apart from
// this code, what a change of any byte does to it, the key file's checks with real file modes,
// and the gate's freshness and replay rules.
#include "ipc/command_signature.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "core/error.hpp"

namespace hapticsim {
namespace {

CommandKey CountingKey() {
  CommandKey key{};
  for (std::size_t k = 0; k < key.size(); ++k) key[k] = static_cast<unsigned char>(k);
  return key;
}

command_t APin(std::int64_t utime) {
  command_t pin{};
  pin.utime = utime;
  pin.command = command_t::PIN_CONFIGURATION;
  pin.primary_size = 3, pin.secondary_lod = 2, pin.secondary_rate_hz = 1000;
  return pin;
}

std::string Hex(const std::uint8_t* bytes, std::size_t n) {
  std::string out;
  char byte[3];
  for (std::size_t k = 0; k < n; ++k) {
    std::snprintf(byte, sizeof byte, "%02x", bytes[k]);
    out += byte;
  }
  return out;
}

std::string TempPath(const std::string& name) {
  const std::string path = ::testing::TempDir() + "command_signature_" + name;
  std::filesystem::remove(path);
  return path;
}

// The wire format a sender in another language must reproduce, pinned by a value computed apart
// from this code: Python's hmac over the LCM big-endian encoding written out by hand,
//   struct.pack('>qqidiid', fingerprint, utime, 2, 0.0, 3, 2, 1000.0) + bytes(32),
// the fingerprint as a signed int64, after b"HAPTIC_COMMAND\0", with the key 00 01 02 … 1f
// (tools/sign_command.py, a sender's signing in Python, checks the same value).
TEST(CommandSignature, MatchesAnHmacSha256ComputedApartOverTheChannelAndTheLcmEncoding) {
  command_t pin = APin(1765000000123456);
  std::vector<std::uint8_t> wire(static_cast<std::size_t>(pin.getEncodedSize()));
  ASSERT_EQ(pin.encode(wire.data(), 0, static_cast<int>(wire.size())),
            static_cast<int>(wire.size()));
  EXPECT_EQ(Hex(wire.data(), wire.size()),
            "fbc78572241ae5da00064542160932400000000200000000000000000000000300000002408f"
            "4000000000000000000000000000000000000000000000000000000000000000000000000000")
      << "command_t's encoding changed: senders in other languages must change with it";
  SignCommand(&pin, "HAPTIC_COMMAND", CountingKey());
  EXPECT_EQ(Hex(pin.mac, sizeof pin.mac),
            "f5e78cdec24fa5f32d05720a0dae474da8a2001fda3b1038e3f3a7af510939bf");
  EXPECT_TRUE(SignatureMatches(pin, "HAPTIC_COMMAND", CountingKey()));
}

TEST(CommandSignature, AChangeOfAnyFieldTheChannelOrTheKeyBreaksIt) {
  command_t signed_pin = APin(1765000000123456);
  SignCommand(&signed_pin, "HAPTIC_COMMAND", CountingKey());
  ASSERT_TRUE(SignatureMatches(signed_pin, "HAPTIC_COMMAND", CountingKey()));
  // Every byte of the encoding, flipped one at a time and decoded again: no forgery passes.
  std::vector<std::uint8_t> wire(static_cast<std::size_t>(signed_pin.getEncodedSize()));
  signed_pin.encode(wire.data(), 0, static_cast<int>(wire.size()));
  int decoded = 0;
  for (std::size_t k = 0; k < wire.size(); ++k) {
    std::vector<std::uint8_t> changed = wire;
    changed[k] ^= 0x01;
    command_t forged{};
    if (forged.decode(changed.data(), 0, static_cast<int>(changed.size())) < 0) continue;
    ++decoded;
    EXPECT_FALSE(SignatureMatches(forged, "HAPTIC_COMMAND", CountingKey())) << "byte " << k;
  }
  EXPECT_EQ(decoded, static_cast<int>(wire.size()) - 8) << "all but the fingerprint decode";
  EXPECT_FALSE(SignatureMatches(signed_pin, "HAPTIC_COMMAND2", CountingKey()));
  CommandKey other = CountingKey();
  other[31] ^= 0x80;
  EXPECT_FALSE(SignatureMatches(signed_pin, "HAPTIC_COMMAND", other));
  EXPECT_FALSE(SignatureMatches(APin(1765000000123456), "HAPTIC_COMMAND", CountingKey()))
      << "an unsigned command (mac all zero)";
}

TEST(CommandSignature, TheGateTakesAFreshSignedCommandOnceAndNothingElse) {
  const std::int64_t start = 1765000000000000, now = start + 10'000'000;
  SignedCommandGate gate(CountingKey(), "HAPTIC_COMMAND", start);
  auto signed_at = [](std::int64_t utime, const CommandKey& key) {
    command_t pin = APin(utime);
    SignCommand(&pin, "HAPTIC_COMMAND", key);
    return pin;
  };
  CommandKey wrong = CountingKey();
  wrong[0] = 0xff;
  // A refused command changes nothing: the good one after it is still taken.
  EXPECT_NE(gate.Refusal(signed_at(now, wrong), now).find("signature does not match"),
            std::string::npos);
  EXPECT_NE(gate.Refusal(APin(now), now).find("signature does not match"), std::string::npos);
  EXPECT_EQ(gate.Refusal(signed_at(now - 1000, CountingKey()), now), "");
  EXPECT_EQ(gate.Refusal(signed_at(now - 1000, CountingKey()), now), "taken before: a replay")
      << "the same command again";
  EXPECT_EQ(gate.Refusal(signed_at(now - 1000, CountingKey()), now + 1'500'000),
            "taken before: a replay")
      << "again, later within the window";
  // Two senders whose commands cross on the bus: an older, different one is still taken.
  EXPECT_EQ(gate.Refusal(signed_at(now - 2000, CountingKey()), now), "") << "an older one";
  EXPECT_EQ(gate.Refusal(signed_at(now - 999, CountingKey()), now), "") << "a later one";
  EXPECT_NE(gate.Refusal(signed_at(now - kCommandFreshnessUs - 1, CountingKey()), now)
                .find("stale, replayed, or a clock to set"),
            std::string::npos);
  EXPECT_NE(
      gate.Refusal(signed_at(now + kCommandFreshnessUs + 1, CountingKey()), now).find("either way"),
      std::string::npos)
      << "from the future";
  EXPECT_EQ(gate.Refusal(signed_at(now + kCommandFreshnessUs, CountingKey()), now), "")
      << "at the edge of the window";
  // A signed utime at either end of int64: refused, without overflow (UBSan checks the build).
  for (std::int64_t utime :
       {std::numeric_limits<std::int64_t>::min(), std::numeric_limits<std::int64_t>::max()}) {
    EXPECT_NE(gate.Refusal(signed_at(utime, CountingKey()), now).find("ms from the daemon's clock"),
              std::string::npos)
        << utime;
  }
  // Recorded before the daemon started, played within the window after a restart: refused.
  SignedCommandGate restarted(CountingKey(), "HAPTIC_COMMAND", start);
  EXPECT_NE(restarted.Refusal(signed_at(start - 1, CountingKey()), start + 1000)
                .find("signed before the daemon started: a replay"),
            std::string::npos);
}

// A command taken, forgotten once the window passed, then played back after the wall clock
// stepped back to its time (NTP, date -s, a restored VM): still refused.
TEST(CommandSignature, AClockSteppedBackDoesNotMakeAForgottenCommandFreshAgain) {
  const std::int64_t start = 1765000000000000, now = start + 10'000'000;
  SignedCommandGate gate(CountingKey(), "HAPTIC_COMMAND", start);
  command_t taken = APin(now);
  SignCommand(&taken, "HAPTIC_COMMAND", CountingKey());
  ASSERT_EQ(gate.Refusal(taken, now), "");
  const std::int64_t later = now + 3 * kCommandFreshnessUs;  // a signed command purges it
  command_t newer = APin(later);
  SignCommand(&newer, "HAPTIC_COMMAND", CountingKey());
  ASSERT_EQ(gate.Refusal(newer, later), "");
  EXPECT_NE(gate.Refusal(taken, now + 1000).find("a replay (or the wall clock stepped back)"),
            std::string::npos);
}

// The gate remembers what it took only within the window, and at most kMaxRemembered of them:
// past that, a flood of signed commands (a key holder's) is refused until the oldest expire.
TEST(CommandSignature, TheGateRemembersAtMostItsWindowsWorth) {
  const std::int64_t start = 1765000000000000, now = start + 10'000'000;
  SignedCommandGate gate(CountingKey(), "HAPTIC_COMMAND", start);
  auto signed_at = [](std::int64_t utime) {
    command_t pin = APin(utime);
    SignCommand(&pin, "HAPTIC_COMMAND", CountingKey());
    return pin;
  };
  for (std::size_t k = 0; k < SignedCommandGate::kMaxRemembered; ++k) {
    ASSERT_EQ(gate.Refusal(signed_at(now + static_cast<std::int64_t>(k)), now), "") << k;
  }
  EXPECT_NE(gate.Refusal(signed_at(now + 100'000), now).find("more than 256 signed commands"),
            std::string::npos);
  const std::int64_t later = now + kCommandFreshnessUs + 1000;  // the first ones expired
  EXPECT_EQ(gate.Refusal(signed_at(later), later), "");
  EXPECT_NE(gate.Refusal(signed_at(now), later).find("ms from the daemon's clock"),
            std::string::npos)
      << "forgotten, but stale";
}

TEST(CommandKeyFile, AMadeKeyIsPrivateRandomAndNeverOverwritten) {
  const std::string first = TempPath("first.key"), second = TempPath("second.key");
  WriteNewCommandKey(first);
  WriteNewCommandKey(second);
  struct stat info {};
  ASSERT_EQ(stat(first.c_str(), &info), 0);
  EXPECT_EQ(info.st_mode & 0777, 0600u);
  EXPECT_NE(ReadCommandKey(first), ReadCommandKey(second));
  const CommandKey kept = ReadCommandKey(first);
  try {
    WriteNewCommandKey(first);
    ADD_FAILURE() << "an existing key was overwritten";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("never overwritten"), std::string::npos) << e.what();
  }
  EXPECT_EQ(ReadCommandKey(first), kept);
}

TEST(CommandKeyFile, AKeyOthersCanReadOrChangeOrThatIsMalformedIsRefusedByName) {
  const std::string path = TempPath("checked.key");
  auto refusal = [&path] {
    try {
      ReadCommandKey(path);
      return std::string("accepted");
    } catch (const Error& e) {
      return std::string(e.what());
    }
  };
  EXPECT_NE(refusal().find("does not exist; make one with `hapticsim ctl --make-key " + path),
            std::string::npos)
      << "missing";
  std::ofstream(path) << "000102030405060708090a0b0c0d0e0f101112131415161718191a1b1c1d1e1f\n";
  for (mode_t mode : {0644, 0604, 0620, 0660}) {
    ASSERT_EQ(chmod(path.c_str(), mode), 0);
    EXPECT_NE(refusal().find("other users could read or change the key; chmod 0600"),
              std::string::npos)
        << std::oct << mode << ": " << refusal();
  }
  for (mode_t mode : {0600, 0640, 0400}) {
    ASSERT_EQ(chmod(path.c_str(), mode), 0);
    EXPECT_EQ(refusal(), "accepted") << std::oct << mode;
  }
  EXPECT_EQ(ReadCommandKey(path), CountingKey());
  if (geteuid() == 0) {  // another user's key could be replaced by that user
    ASSERT_EQ(chown(path.c_str(), 65534, 65534), 0);
    EXPECT_NE(refusal().find("is owned by uid 65534: only root or this process's user"),
              std::string::npos)
        << refusal();
    ASSERT_EQ(chown(path.c_str(), 0, 0), 0);
  }
  for (const char* text :
       {"", "0001", "zz0102030405060708090a0b0c0d0e0f101112131415161718191a1b1c1d1e1f",
        "000102030405060708090a0b0c0d0e0f101112131415161718191a1b1c1d1e1f00"}) {
    std::filesystem::remove(path);
    std::ofstream(path) << text;
    ASSERT_EQ(chmod(path.c_str(), 0600), 0);
    EXPECT_NE(refusal().find("must hold 64 hexadecimal digits"), std::string::npos)
        << "'" << text << "': " << refusal();
  }
  const std::string link = TempPath("link.key");
  ASSERT_EQ(symlink(path.c_str(), link.c_str()), 0);
  try {
    ReadCommandKey(link);
    ADD_FAILURE() << "a key read through a symbolic link";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("is a symbolic link: name the file itself"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace hapticsim
