#!/usr/bin/env bash
# The Debian package on a clean Debian 12 with systemd running: a minimal bookworm made by
# debootstrap, booted with systemd as PID 1 in namespaces of its own (PID, mount, UTS, IPC,
# cgroup under a cgroup of its own, and network: only its own loopback, so the daemon's LCM never
# reaches the host's network), told it is a container, with /proc/sys read-only and a /dev of
# its own, so it changes nothing of the host's. In it:
# `dpkg -i hapticsim_*.deb` with the machine's network cut (its dependencies fetched
# beforehand from Debian's archive), then the service must be active, answer a simulated device's
# press over LCM, and stop when the package is removed. A long-form check (a few minutes, ~150 MB
# from deb.debian.org), not part of scripts/test.sh; docs/simulator.md, "The Debian package".
# Usage (root): scripts/check-deb-on-clean-debian.sh [BUILD_DIR] [WORK_DIR]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="$(realpath "${1:-$root/build}")"
work="$(realpath -m "${2:-/var/tmp/hapticsim-clean-debian}")"
[ "$(id -u)" -eq 0 ] || { echo "check-deb: run as root (debootstrap, chroot, namespaces)"; exit 2; }
command -v debootstrap >/dev/null ||
  { echo "check-deb: needs debootstrap: apt-get install debootstrap"; exit 2; }
fail() { echo "check-deb: FAIL: $*"; exit 1; }
step() { echo "check-deb: $*"; }
marker=".hapticsim-clean-debian"

unshare_pid="" cgroups="" system_pid=""
cleanup() {
  [ -n "${HAPTICSIM_KEEP_MACHINE:-}" ] && return
  # unshare --kill-child: its end takes the machine's PID 1, and with it the whole machine.
  if [ -n "$unshare_pid" ]; then
    kill -9 "$unshare_pid" 2>/dev/null || true
    wait "$unshare_pid" 2>/dev/null || true
  fi
  if [ -n "$cgroups" ] && mountpoint -q "$cgroups"; then
    sleep 0.5
    find "$cgroups/hapticsim-check" -depth -type d -exec rmdir {} + 2>/dev/null || true
    umount "$cgroups"
  fi
}
trap cleanup EXIT

# The work folder is deleted whole: only one this script made, with nothing mounted in it.
if [ -e "$work" ]; then
  [ -f "$work/$marker" ] || fail "$work exists and is not this script's (no $marker): choose another"
  ! findmnt -R -n -o TARGET | grep -q "^$work/" || fail "something is still mounted under $work"
  rm -rf --one-file-system "$work"
fi
mkdir -p "$work/deb"
touch "$work/$marker"
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
# In a mount namespace of its own: its /proc goes with it, whatever happens.
unshare --mount chroot "$machine" sh -c "mount -t proc proc /proc && apt-get clean &&
  apt-get update -qq && apt-get install -y -qq --download-only $package >/dev/null" ||
  fail "apt-get --download-only"

step "booting it: systemd as PID 1, no network but its own loopback"
# pivot_root rather than chroot: the machine's root must be a mount of its own for the service's
# sandboxing (ProtectSystem= and the other mount namespacing of the unit).
# Its cgroups under one of its own (a cgroup namespace rooted there), removed at the end.
cgroups="$work/cgroups"
mkdir -p "$cgroups"
mount -t cgroup2 none "$cgroups"
mkdir "$cgroups/hapticsim-check"
# /dev: a tmpfs with the host's few harmless nodes and its own devpts and shm, not the host's
# devtmpfs; /proc/sys read-only; container= so systemd knows it is not the host's init.
sh -c 'echo $$ > "$1/hapticsim-check/cgroup.procs" && shift && exec "$@"' sh "$cgroups" \
  unshare --kill-child --fork --pid --mount --uts --ipc --net --cgroup /bin/sh -c \
  'mount --make-rprivate / && mount --bind "$1" "$1" && cd "$1" &&
   mount -t tmpfs -o mode=755,nosuid dev dev &&
   for d in null zero full random urandom tty; do touch dev/$d && mount --bind /dev/$d dev/$d; done &&
   mkdir -p dev/pts dev/shm && mount -t devpts -o newinstance,ptmxmode=666 devpts dev/pts &&
   ln -s pts/ptmx dev/ptmx && mount -t tmpfs -o mode=1777,nosuid,nodev shm dev/shm &&
   mkdir -p .oldroot && pivot_root . .oldroot &&
   exec /bin/sh -c "mount -t proc proc /proc && mount --bind /proc/sys /proc/sys &&
     mount -o remount,bind,ro /proc/sys && umount -l /.oldroot && rmdir /.oldroot &&
     mount -t sysfs -o ro sys /sys && mount -t tmpfs tmpfs /run && mount -t tmpfs tmpfs /tmp &&
     mount -t cgroup2 cgroup2 /sys/fs/cgroup &&
     exec env container=hapticsim-check /lib/systemd/systemd --system"' \
  sh "$machine" >"$work/boot.log" 2>&1 &
unshare_pid=$!
for _ in $(seq 1 50); do
  # unshare's child (sh above became unshare): after two execs, the machine's systemd.
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
step "systemd is $state"

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
kill -0 "$system_pid" 2>/dev/null || fail "the machine is gone"
state=$(inside systemctl is-active hapticsimd 2>/dev/null || true)
case "$state" in inactive | unknown) ;; *) fail "hapticsimd is '$state' after removal" ;; esac
step "PASS: installed, started, answered, removed and stopped on a clean Debian 12"
