#!/usr/bin/env bash
# What hapticsimd costs when nothing touches the object, with the regions sleeping at rest and
# without: its CPU time (utime + stime from /proc) over SECONDS with no device, then over SECONDS
# with a simulated device hovering 1-2 mm above the surface over LCM. Runs in a private network
# namespace of its own (LCM stays there). Needs a build (scripts/build.sh).
# Usage: scripts/measure-idle-cpu.sh [SECONDS]   (default 20)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
if [ "${HAPTICSIM_IN_NETNS:-}" != 1 ]; then
  HAPTICSIM_IN_NETNS=1 exec "$root/tests/support/in_private_netns.sh" "$0" "$@"
fi
seconds="${1:-20}"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
ticks_per_s="$(getconf CLK_TCK)"
cpu_ticks() { awk '{print $14 + $15}' "/proc/$1/stat"; }
percent() { awk -v t="$1" -v s="$seconds" -v hz="$ticks_per_s" 'BEGIN {printf "%.2f", 100 * t / hz / s}'; }

for sleep_at_rest in true false; do
  printf '[lcm]\nurl = "udpm://239.255.76.67:7667?ttl=0"\n[realtime]\nsleep_at_rest = %s\n' \
    "$sleep_at_rest" >"$work/hapticsimd.toml"
  "$root/build/daemon/hapticsimd" --config "$work/hapticsimd.toml" >"$work/daemon.log" 2>&1 &
  daemon=$!
  sleep 3
  before=$(cpu_ticks $daemon); sleep "$seconds"; after=$(cpu_ticks $daemon)
  idle=$(percent $((after - before)))
  "$root/build/tools/hapticsim" device --input press --amplitude 0 --frequency 0.01 \
    --duration $((seconds + 4)) >"$work/device.txt" 2>&1 &
  device=$!
  sleep 2
  before=$(cpu_ticks $daemon); sleep "$seconds"; after=$(cpu_ticks $daemon)
  hovering=$(percent $((after - before)))
  wait $device
  kill -TERM $daemon && wait $daemon
  echo "sleep_at_rest = $sleep_at_rest: no device ${idle} % of a core; device hovering ${hovering} % of a core"
done
