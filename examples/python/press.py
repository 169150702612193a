#!/usr/bin/env python3
"""Drive hapticsimd from Python through its C API (libhapticsim_client.so) with ctypes.

Holds the tool 2 mm above the default scene's contact node, presses 1 cm in and back over 2 s at
about 1 kHz (Python's sleeps are not a real-time loop: this is for scripts and tests, not for a
device), and prints what the daemon answered.

    python3 press.py [--socket PATH] [--library PATH/TO/libhapticsim_client.so]

Exit status: 0 when at least 90 % of the poses were answered and the press was felt (over
0.5 N), 1 when not, 2 when it could not connect.
"""
import argparse
import ctypes
import ctypes.util
import math
import sys
import time

FLAG_IN_CONTACT = 1  # HAPTICSIM_FLAG_IN_CONTACT


class Force(ctypes.Structure):
    """hapticsim_force"""
    _fields_ = [("period", ctypes.c_int64), ("seq", ctypes.c_int64),
                ("first_seq", ctypes.c_int64), ("utime_us", ctypes.c_int64),
                ("force_n", ctypes.c_double * 3), ("error_percent", ctypes.c_double),
                ("flags", ctypes.c_int32)]


class Status(ctypes.Structure):
    """hapticsim_status"""
    _fields_ = [("daemon_pid", ctypes.c_int64), ("daemon_running", ctypes.c_int32),
                ("heartbeat_ns", ctypes.c_int64), ("newest_period", ctypes.c_int64),
                ("poses_sent", ctypes.c_int64)]


def load(path):
    path = path or ctypes.util.find_library("hapticsim_client")
    if not path:
        sys.exit("press.py: libhapticsim_client.so not found: pass --library, or install hapticsim")
    lib = ctypes.CDLL(path)
    lib.hapticsim_connect.restype = ctypes.c_void_p
    lib.hapticsim_connect.argtypes = [ctypes.c_char_p, ctypes.c_char_p, ctypes.c_size_t]
    lib.hapticsim_disconnect.argtypes = [ctypes.c_void_p]
    lib.hapticsim_send_pose.argtypes = [ctypes.c_void_p, ctypes.c_int64, ctypes.c_int64,
                                        ctypes.POINTER(ctypes.c_double * 3)]
    lib.hapticsim_read_force.argtypes = [ctypes.c_void_p, ctypes.POINTER(Force)]
    lib.hapticsim_is_live.argtypes = [ctypes.c_void_p, ctypes.c_int64]
    lib.hapticsim_read_status.argtypes = [ctypes.c_void_p, ctypes.POINTER(Status)]
    lib.hapticsim_client_version.restype = ctypes.c_char_p
    return lib


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--socket", help="hapticsimd's shm.socket (default: its default)")
    parser.add_argument("--library", help="path of libhapticsim_client.so")
    args = parser.parse_args()
    lib = load(args.library)
    why = ctypes.create_string_buffer(512)
    client = lib.hapticsim_connect(args.socket.encode() if args.socket else None, why, len(why))
    if not client:
        print("press.py:", why.value.decode(), file=sys.stderr)  # says what to fix
        return 2
    edge_m, depth_m, periods = 0.25, 0.01, 2000
    answered = in_contact = 0
    peak_n = 0.0
    force = Force()
    start = time.monotonic()
    for seq in range(1, periods + 1):
        release = start + (seq - 1) * 1e-3
        time.sleep(max(0.0, release - time.monotonic()))
        t = seq / periods
        z = -0.002 if t < 0.2 else depth_m * 0.5 * (1 - math.cos(2 * math.pi * (t - 0.2) / 0.8))
        lib.hapticsim_send_pose(client, seq, int(release * 1e6),
                                ctypes.byref((ctypes.c_double * 3)(edge_m / 2, edge_m / 2, z)))
        if not lib.hapticsim_is_live(client, time.monotonic_ns()):
            continue
        if lib.hapticsim_read_force(client, ctypes.byref(force)) != 1 or force.seq < 0:
            continue
        answered += 1
        in_contact += bool(force.flags & FLAG_IN_CONTACT)
        peak_n = max(peak_n, math.sqrt(sum(f * f for f in force.force_n)))
    status = Status()
    lib.hapticsim_read_status(client, ctypes.byref(status))
    lib.hapticsim_disconnect(client)
    print(f"press.py: hapticsim_client {lib.hapticsim_client_version().decode()}, daemon pid "
          f"{status.daemon_pid}; {periods} poses sent ({status.poses_sent} counted): {answered} "
          f"answered, {in_contact} in contact; peak force {peak_n:.3f} N")
    return 0 if answered >= periods * 0.9 and in_contact > 0 and peak_n > 0.5 else 1


if __name__ == "__main__":
    sys.exit(main())
