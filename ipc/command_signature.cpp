#include "ipc/command_signature.hpp"

#include <fcntl.h>
#include <openssl/crypto.h>
#include <openssl/evp.h>
#include <openssl/hmac.h>
#include <sys/random.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <optional>
#include <vector>

#include "core/error.hpp"
#include "ipc/file_mode.hpp"
#include "ipc/unique_fd.hpp"

namespace hapticsim {
namespace {

using Mac = std::array<unsigned char, 32>;
static_assert(sizeof(command_t::mac) == sizeof(Mac), "command_t.mac holds an HMAC-SHA256");

// The MAC of `command` as signed for `channel`; nothing when it cannot be computed, so that no
// failure can make an all-zero MAC (an unsigned command's) count as valid.
std::optional<Mac> MacOf(const command_t& command, const std::string& channel,
                         const CommandKey& key) {
  command_t unsigned_copy = command;
  std::memset(unsigned_copy.mac, 0, sizeof unsigned_copy.mac);
  // The channel, a NUL, then the LCM encoding: a command signed for one channel is not valid on
  // another, and the encoding starts with the type's fingerprint.
  std::vector<unsigned char> message(channel.begin(), channel.end());
  message.push_back(0);
  const std::size_t head = message.size();
  const int size = unsigned_copy.getEncodedSize();
  message.resize(head + static_cast<std::size_t>(size));
  if (unsigned_copy.encode(message.data() + head, 0, size) != size) return std::nullopt;
  Mac mac{};
  unsigned int length = 0;
  if (HMAC(EVP_sha256(), key.data(), static_cast<int>(key.size()), message.data(), message.size(),
           mac.data(), &length) == nullptr ||
      length != mac.size()) {
    return std::nullopt;
  }
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
  shm::UniqueFd fd(open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW | O_NONBLOCK | O_NOCTTY));
  if (!fd) {
    const int error = errno;
    if (error == ENOENT) {
      throw Error(what + " does not exist; make one with `hapticsim ctl --make-key " + path + "`");
    }
    if (error == EACCES) {
      throw Error(what + " cannot be read by this process (uid " + std::to_string(geteuid()) +
                  "); under systemd (DynamicUser) hand it to the service with LoadCredential= "
                  "and name the copy in /run/credentials (docs/operations.md)");
    }
    if (error == ELOOP) throw Error(what + " is a symbolic link: name the file itself");
    throw Error(what + " cannot be opened (" + std::strerror(error) + ")");
  }
  struct stat info {};
  if (fstat(fd.get(), &info) != 0 || !S_ISREG(info.st_mode)) {
    throw Error(what + " is not a regular file");
  }
  if (info.st_uid != 0 && info.st_uid != geteuid()) {
    throw Error(what + " is owned by uid " + std::to_string(info.st_uid) +
                ": only root or this process's user (uid " + std::to_string(geteuid()) +
                ") may own it, as its owner can replace the key");
  }
  if (info.st_mode & 0027) {
    throw Error(what + " has mode " + shm::OctalMode(info.st_mode) +
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
  bool whole = digits.size() == 2 * key.size() && got < static_cast<ssize_t>(sizeof text);
  for (std::size_t k = 0; whole && k < key.size(); ++k) {
    const int high = HexDigit(digits[2 * k]), low = HexDigit(digits[2 * k + 1]);
    whole = high >= 0 && low >= 0;
    key[k] = static_cast<unsigned char>(high * 16 + low);
  }
  OPENSSL_cleanse(text, sizeof text);  // no copy of the key left behind but the one returned
  OPENSSL_cleanse(digits.data(), digits.size());
  if (whole) return key;
  OPENSSL_cleanse(key.data(), key.size());
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
  const bool written =
      write(fd.get(), text.data(), text.size()) == static_cast<ssize_t>(text.size()) &&
      fsync(fd.get()) == 0;
  const std::string reason = std::strerror(errno);
  OPENSSL_cleanse(text.data(), text.size());
  if (!written) {
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
  const std::optional<Mac> mac = MacOf(*command, channel, key);
  if (!mac) throw Error("the command could not be signed (OpenSSL's HMAC-SHA256 failed)");
  std::memcpy(command->mac, mac->data(), mac->size());
}

bool SignatureMatches(const command_t& command, const std::string& channel, const CommandKey& key) {
  const std::optional<Mac> mac = MacOf(command, channel, key);
  return mac && CRYPTO_memcmp(mac->data(), command.mac, mac->size()) == 0;
}

SignedCommandGate::SignedCommandGate(const CommandKey& key, std::string channel,
                                     std::int64_t start_us)
    : key_(key), channel_(std::move(channel)), start_us_(start_us), latest_now_us_(start_us) {}

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
  if (command.utime <= start_us_) {
    return "signed before the daemon started: a replay (or the wall clock stepped back)";
  }
  // A clock stepped back must not make a command forgotten below fresh again: older than the
  // window on the latest clock reading seen is stale whatever the clock says now.
  latest_now_us_ = std::max(latest_now_us_, now_us);
  if (command.utime < latest_now_us_ - kCommandFreshnessUs) {
    return "signed before the window of the latest clock reading: a replay (or the wall clock "
           "stepped back)";
  }
  // Only commands still within the window need remembering: older ones fail the check above.
  std::erase_if(taken_,
                [&](const Taken& t) { return t.utime_us < latest_now_us_ - kCommandFreshnessUs; });
  for (const Taken& t : taken_) {
    if (CRYPTO_memcmp(t.mac.data(), command.mac, t.mac.size()) == 0) {
      return "taken before: a replay";
    }
  }
  if (taken_.size() >= kMaxRemembered) {
    return "more than " + std::to_string(kMaxRemembered) + " signed commands within " +
           std::to_string(kCommandFreshnessUs / 1000) + " ms";
  }
  Taken taken{command.utime, {}};
  std::memcpy(taken.mac.data(), command.mac, taken.mac.size());
  taken_.push_back(taken);
  return "";
}

}  // namespace hapticsim
