#include "ipc/command_signature.hpp"

#include <fcntl.h>
#include <openssl/crypto.h>
#include <openssl/evp.h>
#include <openssl/hmac.h>
#include <sys/random.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <vector>

#include "core/error.hpp"
#include "ipc/unique_fd.hpp"

namespace hapticsim {
namespace {

using Mac = std::array<unsigned char, 32>;
static_assert(sizeof(command_t::mac) == sizeof(Mac), "command_t.mac holds an HMAC-SHA256");

std::string Octal(mode_t mode) {
  char text[8];
  std::snprintf(text, sizeof text, "%04o", static_cast<unsigned>(mode & 07777));
  return text;
}

Mac MacOf(const command_t& command, const std::string& channel, const CommandKey& key) {
  command_t unsigned_copy = command;
  std::memset(unsigned_copy.mac, 0, sizeof unsigned_copy.mac);
  // The channel, a NUL, then the LCM encoding: a command signed for one channel is not valid on
  // another, and the encoding starts with the type's fingerprint.
  std::vector<unsigned char> message(channel.begin(), channel.end());
  message.push_back(0);
  const std::size_t head = message.size();
  message.resize(head + static_cast<std::size_t>(unsigned_copy.getEncodedSize()));
  unsigned_copy.encode(message.data() + head, 0, static_cast<int>(message.size() - head));
  Mac mac{};
  unsigned int length = 0;
  HMAC(EVP_sha256(), key.data(), static_cast<int>(key.size()), message.data(), message.size(),
       mac.data(), &length);
  return mac;
}

int HexDigit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

}  // namespace

CommandKey ReadCommandKey(const std::string& path) {
  const std::string what = "the command key file " + path;
  shm::UniqueFd fd(open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW | O_NONBLOCK));
  if (!fd) {
    throw Error(what + " cannot be opened (" + std::strerror(errno) +
                "); make one with `hapticsim ctl --make-key " + path + "`");
  }
  struct stat info {};
  if (fstat(fd.get(), &info) != 0 || !S_ISREG(info.st_mode)) {
    throw Error(what + " is not a regular file");
  }
  if (info.st_mode & 0027) {
    throw Error(what + " has mode " + Octal(info.st_mode) +
                ": other users could read or change the key; chmod 0600 (or 0640 for a group "
                "of senders) " +
                path);
  }
  char text[256];
  const ssize_t got = read(fd.get(), text, sizeof text);
  if (got < 0) throw Error(what + " cannot be read (" + std::strerror(errno) + ")");
  std::string digits;
  for (ssize_t k = 0; k < got; ++k) {
    if (!std::isspace(static_cast<unsigned char>(text[k]))) digits += text[k];
  }
  CommandKey key{};
  const bool hex = digits.size() == 2 * key.size() && got < static_cast<ssize_t>(sizeof text);
  for (std::size_t k = 0; hex && k < key.size(); ++k) {
    const int high = HexDigit(digits[2 * k]), low = HexDigit(digits[2 * k + 1]);
    if (high < 0 || low < 0) break;
    key[k] = static_cast<unsigned char>(high * 16 + low);
    if (k + 1 == key.size()) return key;
  }
  throw Error(what + " must hold 64 hexadecimal digits (a 256-bit key), e.g. from `openssl " +
              "rand -hex 32` or `hapticsim ctl --make-key FILE`");
}

void WriteNewCommandKey(const std::string& path) {
  CommandKey key{};
  if (getrandom(key.data(), key.size(), 0) != static_cast<ssize_t>(key.size())) {
    throw Error(std::string("no random bytes for a key: ") + std::strerror(errno));
  }
  shm::UniqueFd fd(open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0600));
  if (!fd) {
    throw Error("cannot make the key file " + path + " (" + std::strerror(errno) +
                (errno == EEXIST ? "; a key is never overwritten: remove the old one first" : "") +
                ")");
  }
  std::string text;
  char byte[3];
  for (unsigned char b : key) {
    std::snprintf(byte, sizeof byte, "%02x", b);
    text += byte;
  }
  text += "\n";
  OPENSSL_cleanse(key.data(), key.size());
  if (write(fd.get(), text.data(), text.size()) != static_cast<ssize_t>(text.size()) ||
      fsync(fd.get()) != 0) {
    const std::string reason = std::strerror(errno);
    unlink(path.c_str());
    throw Error("cannot write the key file " + path + " (" + reason + ")");
  }
}

std::int64_t CommandClockUs() {
  timespec now{};
  clock_gettime(CLOCK_REALTIME, &now);
  return static_cast<std::int64_t>(now.tv_sec) * 1'000'000 + now.tv_nsec / 1000;
}

void SignCommand(command_t* command, const std::string& channel, const CommandKey& key) {
  const Mac mac = MacOf(*command, channel, key);
  std::memcpy(command->mac, mac.data(), mac.size());
}

bool SignatureMatches(const command_t& command, const std::string& channel, const CommandKey& key) {
  const Mac mac = MacOf(command, channel, key);
  return CRYPTO_memcmp(mac.data(), command.mac, mac.size()) == 0;
}

SignedCommandGate::SignedCommandGate(const CommandKey& key, std::string channel,
                                     std::int64_t start_us)
    : key_(key), channel_(std::move(channel)), last_accepted_us_(start_us) {}

std::string SignedCommandGate::Refusal(const command_t& command, std::int64_t now_us) {
  // The signature first: nothing about an unsigned command may change what the gate remembers.
  if (!SignatureMatches(command, channel_, key_)) {
    return "its signature does not match lcm.command_key_file (unsigned, another key, or "
           "changed on the way)";
  }
  // In long double: a utime near either end of int64 must not overflow the difference.
  const long double age_us =
      static_cast<long double>(now_us) - static_cast<long double>(command.utime);
  if (age_us > kCommandFreshnessUs || age_us < -kCommandFreshnessUs) {
    char age_ms[32];
    std::snprintf(age_ms, sizeof age_ms, "%.0Lf", age_us / 1000);
    return std::string("signed ") + age_ms + " ms from the daemon's clock (at most " +
           std::to_string(kCommandFreshnessUs / 1000) +
           " ms either way): stale, replayed, or a clock to set";
  }
  if (command.utime <= last_accepted_us_) {
    return "not later than the last command taken (or the daemon's start): a replay";
  }
  last_accepted_us_ = command.utime;
  return "";
}

}  // namespace hapticsim
