#pragma once

#include <array>
#include <cstdint>
#include <deque>
#include <string>

#include "hapticsim/command_t.hpp"

namespace hapticsim {

/**
 * Commands on LCM, authenticated. Anyone who can send on the bus can send a command_t, so the
 * daemon takes one only when it carries a valid HMAC-SHA256 under a key that the daemon and the
 * sender share (lcm.command_key_file), and only once:
 *
 *  - the MAC covers the channel name and the LCM encoding of the command's fields (with `mac`
 *    zeroed), fingerprint included, so no field, type or channel can be changed;
 *  - `utime` is the sender's wall clock (CLOCK_REALTIME, µs). A command must be within
 *    kCommandFreshnessUs of the daemon's clock, later than the daemon's start, and not one taken
 *    before (the gate remembers the MACs it took within the window): a recorded command cannot
 *    be played again, not even after a restart, while commands of several senders may come in
 *    any order.
 *
 * One key per daemon: a command signed for one daemon is valid for another that shares its key
 * and channel, within the window.
 */
using CommandKey = std::array<unsigned char, 32>;

/** How far a signed command's utime may be from the daemon's clock, either way, µs. */
inline constexpr std::int64_t kCommandFreshnessUs = 2'000'000;

/**
 * Reads a key file: 64 hexadecimal digits (256 bits), surrounding white space allowed. The file
 * must be a regular file, not a symbolic link, owned by root or this process's user, that no
 * other user can read or anyone but its owner write (0600, or 0640 for a group of senders).
 * @throws Error naming the file and what to fix.
 */
CommandKey ReadCommandKey(const std::string& path);

/**
 * Makes a new random key file at `path` (mode 0600); refuses to replace an existing one.
 * @throws Error when the file exists or cannot be written.
 */
void WriteNewCommandKey(const std::string& path);

/** The wall clock in µs, as a signed command's utime is. */
std::int64_t CommandClockUs();

/**
 * Sets command->mac for `channel`. Stamp utime (CommandClockUs) first: the MAC covers it.
 * @throws Error when no MAC can be computed (OpenSSL failed).
 */
void SignCommand(command_t* command, const std::string& channel, const CommandKey& key);

/**
 * Whether command.mac is the MAC of the command on `channel` (compared in constant time); false
 * when no MAC can be computed.
 */
bool SignatureMatches(const command_t& command, const std::string& channel, const CommandKey& key);

/**
 * The daemon's side: which LCM commands to take. Not thread-safe; one owner (the LCM bridge, on
 * the I/O thread).
 */
class SignedCommandGate {
 public:
  /** Commands taken within one window at most; more are refused until the oldest expire. */
  static constexpr std::size_t kMaxRemembered = 256;

  /** `start_us`: the daemon's start on CommandClockUs; nothing signed before it is taken. */
  SignedCommandGate(const CommandKey& key, std::string channel, std::int64_t start_us);

  /** "" when `command` is to be taken (and remembered), otherwise why it is refused. */
  std::string Refusal(const command_t& command, std::int64_t now_us);

 private:
  struct Taken {
    std::int64_t utime_us;
    std::array<std::uint8_t, 32> mac;
  };
  CommandKey key_;
  std::string channel_;
  std::int64_t start_us_;
  /** The latest clock reading seen: what is forgotten stays stale if the clock steps back. */
  std::int64_t latest_now_us_;
  std::deque<Taken> taken_;  // the commands taken within the window, oldest first
};

}  // namespace hapticsim
