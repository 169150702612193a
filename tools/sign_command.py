#!/usr/bin/env python3
"""Signing a hapticsim command_t in Python, for a simulator that commands hapticsimd over LCM.

The daemon takes a command on LCM only with lcm.accept_commands = true, and only when its `mac`
is the HMAC-SHA256, under the key in lcm.command_key_file, of the channel name, a NUL byte and
the command's LCM encoding with `mac` all zero; its utime (wall clock, µs) must be within 2 s of
the daemon's clock (docs/operations.md, "Signed commands on LCM").

    sign_command.py --self-test      checks this code against the value the C++ test pins

With the LCM Python bindings (lcm-gen -p lcmtypes/hapticsim_command_t.lcm) a sender does:

    command.utime = int(time.time() * 1e6)
    command.mac = bytes(32)
    command.mac = mac_of(command.encode(), "HAPTIC_COMMAND", key)
    lc.publish("HAPTIC_COMMAND", command.encode())
"""
import hashlib
import hmac
import struct
import sys

# command_t's LCM fingerprint (the first 8 bytes of every encoding), as a signed int64.
FINGERPRINT = -304127724545710630


def mac_of(encoding_with_zero_mac: bytes, channel: str, key: bytes) -> bytes:
    """The MAC a command's encoding (its mac field all zero) must carry on `channel`."""
    return hmac.new(key, channel.encode() + b"\0" + encoding_with_zero_mac, hashlib.sha256).digest()


def encode(utime, command, error_target_percent, primary_size, secondary_lod, secondary_rate_hz,
           mac=bytes(32)) -> bytes:
    """command_t's LCM encoding, written out by hand: big-endian, the fingerprint first."""
    return struct.pack(">qqidiid", FINGERPRINT, utime, command, error_target_percent, primary_size,
                       secondary_lod, secondary_rate_hz) + mac


def self_test() -> int:
    key = bytes(range(32))
    wire = encode(1765000000123456, 2, 0.0, 3, 2, 1000.0)  # PIN_CONFIGURATION 3 2 1000 Hz
    expected_wire = ("fbc78572241ae5da00064542160932400000000200000000000000000000000300000002"
                     "408f4000000000000000000000000000000000000000000000000000000000000000000000"
                     "000000")
    expected_mac = "f5e78cdec24fa5f32d05720a0dae474da8a2001fda3b1038e3f3a7af510939bf"
    ok = wire.hex() == expected_wire and mac_of(wire, "HAPTIC_COMMAND", key).hex() == expected_mac
    mac = mac_of(wire, "HAPTIC_COMMAND", key).hex()
    print("sign_command: " + ("the encoding and the MAC match the C++ test's" if ok
                              else "MISMATCH: " + wire.hex() + " " + mac))
    return 0 if ok else 1


if __name__ == "__main__":
    if sys.argv[1:] == ["--self-test"]:
        sys.exit(self_test())
    print(__doc__)
    sys.exit(2)
