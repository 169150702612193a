#!/usr/bin/env bash
# The Debian package on a clean Debian 12 with systemd running: a minimal bookworm made by
# debootstrap, booted with systemd as PID 1 in namespaces of its own (PID, mount, UTS, IPC and
# network: only its own loopback, so the daemon's LCM never reaches the host's network). In it:
# `dpkg -i hapticsim_*.deb` with the machine's network cut (its dependencies fetched
# beforehand from Debian's archive), then the service must be active, answer a simulated device's
# press over LCM, and stop when the package is removed. A long-form check (a few minutes, ~150 MB
# from deb.debian.org), not part of scripts/test.sh; docs/simulator.md, "The Debian package".
# Usage (root): scripts/check-deb-on-clean-debian.sh [BUILD_DIR] [WORK_DIR]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${1:-$root/build}"
work="${2:-/var/tmp/hapticsim-clean-debian}"
[ "$(id -u)" -eq 0 ] || { echo "check-deb: run as root (debootstrap, chroot, namespaces)"; exit 2; }
command -v debootstrap >/dev/null || apt-get install -y -qq --no-install-recommends debootstrap >/dev/null
fail() { echo "check-deb: FAIL: $*"; exit 1; }
step() { echo "check-deb: $*"; }

system_pid=""
cleanup() {
  # PID 1 of the namespace gone, the namespace and everything in it go too.
  [ -n "$system_pid" ] && [ -z "${HAPTICSIM_KEEP_MACHINE:-}" ] && kill -9 "$system_pid" 2>/dev/null || true
}
trap cleanup EXIT

rm -rf "$work"
mkdir -p "$work/deb"
step "cpack -G DEB from $build"
(cd "$work/deb" && cpack --config "$build/CPackConfig.cmake" -G DEB -B "$work/deb" >cpack.log 2>&1) ||
  { cat "$work/deb/cpack.log"; fail "cpack"; }
deb=$(ls "$work"/deb/*.deb)

machine="$work/root"
step "debootstrap: a minimal Debian 12 with systemd in $machine"
debootstrap --variant=minbase --include=systemd,systemd-sysv,dbus bookworm "$machine" \
  http://deb.debian.org/debian >"$work/debootstrap.log" 2>&1 || { tail "$work/debootstrap.log"; fail "debootstrap"; }
cp "$deb" "$machine/root/"
package="/root/$(basename "$deb")"

step "the package's dependencies, fetched while the machine still has the archive"
chroot "$machine" sh -c "mount -t proc proc /proc && apt-get update -qq &&
  apt-get install -y -qq --download-only $package >/dev/null; status=\$?; umount /proc; exit \$status" ||
  fail "apt-get --download-only"

step "booting it: systemd as PID 1, no network but its own loopback"
# pivot_root rather than chroot: the machine's root must be a mount of its own for the service's
# sandboxing (ProtectSystem= and the other mount namespacing of the unit).
unshare --fork --pid --mount --uts --ipc --net /bin/sh -c \
  'mount --make-rprivate / && mount --bind "$1" "$1" && cd "$1" && mkdir -p .oldroot &&
   pivot_root . .oldroot &&
   exec /bin/sh -c "mount -t proc proc /proc && umount -l /.oldroot && rmdir /.oldroot &&
     mount -t sysfs sys /sys && mount -t tmpfs tmpfs /run && mount -t tmpfs tmpfs /tmp &&
     mount -t cgroup2 cgroup2 /sys/fs/cgroup && exec /lib/systemd/systemd --system"' \
  sh "$machine" >"$work/boot.log" 2>&1 &
unshare_pid=$!
for _ in $(seq 1 50); do
  # unshare's child: after two execs, the machine's systemd (never another machine's).
  candidate=$(pgrep -P "$unshare_pid" || true)
  [ -n "$candidate" ] && [ "$(cat "/proc/$candidate/comm" 2>/dev/null)" = systemd ] && system_pid=$candidate
  [ -n "$system_pid" ] && break
  sleep 0.2
done
[ -n "$system_pid" ] || { cat "$work/boot.log"; fail "systemd did not start"; }
nsenter -t "$system_pid" -n ip link set lo up
nsenter -t "$system_pid" -n ip route add 224.0.0.0/4 dev lo src 127.0.0.1   # as docs/operations.md says
inside() { nsenter -t "$system_pid" -a -r -w "$@"; }
for _ in $(seq 1 30); do
  state=$(inside systemctl is-system-running 2>/dev/null || true)
  case "$state" in running | degraded) break ;; esac
  sleep 1
done
step "systemd is $state (starting: a unit of the bare machine still waits, e.g. a serial getty)"

step "dpkg -i $package with its dependencies, offline"
inside sh -c "dpkg -i /var/cache/apt/archives/*.deb $package" >"$work/install.log" 2>&1 ||
  { cat "$work/install.log"; fail "dpkg -i"; }
grep -i "hapticsim" "$work/install.log" | sed 's/^/  /'
for _ in $(seq 1 20); do
  inside systemctl is-active -q hapticsimd && break
  sleep 0.5
done
inside systemctl status hapticsimd --no-pager -n 12 | sed 's/^/  /' || true
inside systemctl is-active -q hapticsimd || fail "hapticsimd is not active after installing"
inside systemctl is-enabled -q hapticsimd || fail "hapticsimd is not enabled"
getent_group=$(inside getent group hapticsim || true)
[ -n "$getent_group" ] || fail "no hapticsim group"
step "the service is active and enabled; group: $getent_group"

step "a simulated device presses for 3 s over LCM, inside the machine"
inside hapticsim device --input press --duration 3 --json >"$work/device.json" 2>"$work/device.log" ||
  { cat "$work/device.log" "$work/device.json"; fail "hapticsim device"; }
python3 - "$work/device.json" <<'PY' || fail "the device's run"
import json, sys
r = json.load(open(sys.argv[1]))
print(f"  {r['answers']} answers, {r['lost_answers']} lost, largest force {r['max_force_n']:.3f} N, "
      f"largest step in contact {r['max_force_step_in_contact_n']:.3f} N, "
      f"{r['nonfinite_forces']} non-finite")
sys.exit(0 if r["answers"] > 2000 and r["nonfinite_forces"] == 0 and r["max_force_n"] > 0.1 else 1)
PY
inside journalctl -u hapticsimd --no-pager -n 6 -o cat | sed 's/^/  journal: /' || true

step "dpkg --remove hapticsim: the service stops"
inside dpkg --remove hapticsim >"$work/remove.log" 2>&1 || { cat "$work/remove.log"; fail "dpkg --remove"; }
inside systemctl is-active -q hapticsimd && fail "hapticsimd still active after removal"
step "PASS: installed, started, answered, removed and stopped on a clean Debian 12"
