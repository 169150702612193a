#!/usr/bin/env bash
# hapticsimd --no-port-guard on a host's network namespace (an interface besides loopback): refused
# with a message that says why and what to run instead, before any LCM or socket is opened
# (--check-config exits right after the refusal would have been made).
set -u
daemon=$1
# This namespace's interfaces that are up (netlink, as the daemon asks; /sys/class/net shows the
# namespace that mounted sysfs).
others=$(ip -o link show up | awk -F': ' '{print $2}' | grep -v '^lo$' || true)
if [ -z "$others" ]; then
  echo "only loopback here: nothing to refuse on (skipped)"
  exit 77
fi
out=$("$daemon" --no-port-guard --check-config 2>&1)
status=$?
echo "$out"
if [ "$status" -ne 2 ]; then echo "FAILED: exit status $status, want 2"; exit 1; fi
for want in "--no-port-guard is for tests and soaks only" "besides loopback" "hapticsim soak --no-port-guard"; do
  if ! grep -qF -- "$want" <<<"$out"; then echo "FAILED: the message lacks: $want"; exit 1; fi
done
# Without the flag the same check passes: the refusal is the flag's.
"$daemon" --check-config >/dev/null || { echo "FAILED: --check-config alone failed"; exit 1; }
# The soak's marker alone does not make a host a sandbox.
HAPTICSIM_SANDBOX=1 "$daemon" --no-port-guard --check-config >/dev/null 2>&1 &&
  { echo "FAILED: accepted on a host with the marker set"; exit 1; }
echo "refused as it should be"
