#!/usr/bin/env bash
# lcm-spy on a running hapticsimd, the way docs/operations.md says to open it: under Xvfb, in the
# private network namespace this test runs in (tests/support/in_private_netns.sh). Passes when
# lcm-spy starts, finds the hapticsim types on its class path ("Found N LCM types", N ≥ 6: deformation_t among them) and is
# still running after the daemon and a simulated device have talked for two seconds.
# Usage: lcm_spy_test.sh HAPTICSIMD HAPTICSIM LCM_SPY_SH WORK_DIR
set -euo pipefail
daemon_bin="$1" cli="$2" spy="$3" work="$4"
mkdir -p "$work"
pids=()
cleanup() { for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done; wait 2>/dev/null || true; }
trap cleanup EXIT

# A display of our own: Xvfb picks a free number and writes it to the pipe.
exec 3< <(Xvfb -displayfd 1 -screen 0 800x600x24 -nolisten tcp 2>"$work/xvfb.log")
pids+=($!)
read -r -t 20 display <&3 || { echo "Xvfb did not start:"; cat "$work/xvfb.log"; exit 1; }
export DISPLAY=":$display"

"$daemon_bin" >"$work/daemon.log" 2>&1 &
pids+=($!)
DISPLAY=":$display" "$spy" >"$work/spy.log" 2>&1 &
spy_pid=$!
pids+=($spy_pid)
"$cli" device --input sine --duration 2 >"$work/device.log" 2>&1 || true

for _ in $(seq 1 100); do
  grep -q "Found [0-9]* LCM types" "$work/spy.log" && break
  sleep 0.1
done
found=$(sed -n 's/^Found \([0-9]*\) LCM types.*/\1/p' "$work/spy.log" | head -1)
if [ -z "$found" ] || [ "$found" -lt 6 ]; then
  echo "lcm-spy did not find the hapticsim types; its output:"; cat "$work/spy.log"; exit 1
fi
kill -0 "$spy_pid" 2>/dev/null || { echo "lcm-spy exited:"; cat "$work/spy.log"; exit 1; }
if grep -q "Exception" "$work/spy.log"; then
  echo "lcm-spy threw:"; cat "$work/spy.log"; exit 1
fi
echo "lcm-spy found $found LCM types on $DISPLAY and kept running"
