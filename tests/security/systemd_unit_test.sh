#!/usr/bin/env bash
# The shipped unit file passes `systemd-analyze verify` (with ExecStart pointed at the built
# daemon, since verify checks that the executable exists), keeps the directives the daemon relies
# on, and a broken copy is caught — so this test can fail.
# Usage: systemd_unit_test.sh UNIT HAPTICSIMD WORKDIR
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
                 'LimitMEMLOCK=infinity' 'ExecReload=/bin/kill -HUP $MAINPID' 'UMask=0077' \
                 'RuntimeDirectory=hapticsim' 'SupplementaryGroups=hapticsim' \
                 'CapabilityBoundingSet=' 'SystemCallFilter=@system-service' 'IPAddressDeny=any' \
                 'TasksMax=' 'ProtectProc=invisible'; do
  grep -qF -- "$directive" "$unit" || { echo "FAIL: missing $directive"; exit 1; }
done
for directive in 'Type=notify'; do
  grep -qF -- "$directive" "$work/hapticsimd.service" || { echo "FAIL: missing $directive"; exit 1; }
done
if grep -q '^RestrictRealtime' "$work/hapticsimd.service"; then
  echo "FAIL: RestrictRealtime= would forbid the region threads' SCHED_FIFO"; exit 1
fi
sed 's/^Type=notify/Type=notify-bogus/' "$work/hapticsimd.service" > "$work/broken.service"
if [ "$(verify "$work/broken.service")" = "exit 0" ]; then
  echo "FAIL: verify accepted a broken unit: this check proves nothing"; exit 1
fi
# How exposed the service is, by systemd's own measure: at most 2.5 (it was 5.1 MEDIUM).
exposure() {
  systemd-analyze security --offline=yes "$1" 2>&1 | sed -n 's/.*Overall exposure level for [^:]*: \([0-9.]*\).*/\1/p'
}
level=$(exposure "$work/hapticsimd.service")
[ -n "$level" ] || { echo "FAIL: no exposure level from systemd-analyze security"; exit 1; }
if ! awk -v l="$level" 'BEGIN { exit !(l <= 2.5) }'; then
  echo "FAIL: exposure $level > 2.5"; systemd-analyze security --offline=yes "$work/hapticsimd.service"
  exit 1
fi
grep -vE '^(SystemCallFilter|CapabilityBoundingSet|IPAddressDeny|ProtectProc)=' \
  "$work/hapticsimd.service" > "$work/unhardened.service"
unhardened=$(exposure "$work/unhardened.service")
if awk -v l="$unhardened" 'BEGIN { exit !(l <= 2.5) }'; then
  echo "FAIL: the exposure check passes a unit without its hardening ($unhardened)"; exit 1
fi
echo "PASS: the unit verifies (exposure $level; $unhardened without its hardening); a broken copy does not"
