#!/usr/bin/env bash
# The shipped unit file passes `systemd-analyze verify` (with ExecStart pointed at the built
# daemon, since verify checks that the executable exists), keeps the directives the daemon relies
# on, and a broken copy is caught — so this test can fail.
# Usage: verify_unit_test.sh UNIT HAPTICSIMD WORKDIR
set -euo pipefail
unit=$1 daemon=$2 work=$3
mkdir -p "$work"
sed "s|/usr/local/bin/hapticsimd|$daemon|" "$unit" > "$work/hapticsimd.service"
# verify exits 0 on some parse errors ("Failed to parse …, ignoring"): any output is a failure.
verify() { systemd-analyze verify "$1" 2>&1 && echo "exit 0" || echo "exit $?"; }
out=$(verify "$work/hapticsimd.service")
if [ "$out" != "exit 0" ]; then
  echo "FAIL: systemd-analyze verify: $out"; exit 1
fi
for directive in 'Type=notify' 'WatchdogSec=' 'Restart=on-failure' 'LimitRTPRIO=' \
                 'LimitMEMLOCK=infinity' 'ExecReload=/bin/kill -HUP $MAINPID' 'UMask=0077'; do
  grep -qF -- "$directive" "$work/hapticsimd.service" || { echo "FAIL: missing $directive"; exit 1; }
done
if grep -q '^RestrictRealtime' "$work/hapticsimd.service"; then
  echo "FAIL: RestrictRealtime= would forbid the region threads' SCHED_FIFO"; exit 1
fi
sed 's/^Type=notify/Type=notify-bogus/' "$work/hapticsimd.service" > "$work/broken.service"
if [ "$(verify "$work/broken.service")" = "exit 0" ]; then
  echo "FAIL: verify accepted a broken unit: this check proves nothing"; exit 1
fi
echo "PASS: the unit verifies; a broken copy does not"
