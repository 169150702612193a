#!/usr/bin/env bash
# Every system call hapticsimd makes — start, a shared-memory session, LCM, a SIGHUP reload, a
# clean stop — is allowed by the unit's SystemCallFilter= (a call outside it would fail with
# EPERM under systemd: a daemon that cannot start, or worse, one that fails mid-session). Traced
# with strace, compared with the filter expanded by systemd-analyze. A filter without the groups
# the daemon needs is caught too, so this test can fail. Run inside a private network namespace
# (LCM): tests/support/in_private_netns.sh --keep-users (run by root: real time is then granted
# as the unit's LimitRTPRIO grants it, and checked).
# Usage: systemd_syscalls_test.sh UNIT HAPTICSIMD SHM_CLIENT WORKDIR
set -euo pipefail
unit=$1 daemon=$2 client=$3 work=$4
rm -rf "$work" && mkdir -p "$work" && chmod 700 "$work"

# The syscalls a filter allows: its groups expanded recursively, minus ~ lines.
expand() {
  local item
  for item in "$@"; do
    if [[ $item == @* ]]; then
      expand $(systemd-analyze syscall-filter "$item" | tail -n +2 | grep -v '^\s*#' | tr -d ' ')
    else
      echo "$item"
    fi
  done
}
allowed_by() {  # UNIT_FILE
  local allow=() deny=()
  while IFS= read -r value; do
    if [[ $value == ~* ]]; then deny+=(${value#\~}); else allow+=($value); fi
  done < <(sed -n 's/^SystemCallFilter=//p' "$1")
  comm -23 <(expand "${allow[@]}" | sort -u) <(expand "${deny[@]:-}" | sort -u)
}

cat > "$work/hapticsimd.toml" <<TOML
[shm]
enabled = true
socket = "$work/hapticsimd.sock"
group = "$(id -gn)"  # so giving the socket to a group (chown) is traced too
[realtime]
fifo_priority = 10  # as in production: SCHED_FIFO and mlockall are traced too
lock_memory = true
TOML
# The unit's limits, where this user may raise them (root without a user namespace).
ulimit -r 95 2>/dev/null || true
ulimit -l unlimited 2>/dev/null || true
# LeakSanitizer cannot run under ptrace (the sanitizer builds): leaks are checked elsewhere.
export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0"
strace -f -qq -o "$work/trace" "$daemon" --config "$work/hapticsimd.toml" > "$work/daemon.log" 2>&1 &
tracer=$!
trap 'kill -KILL $tracer 2>/dev/null || true' EXIT
for _ in $(seq 300); do grep -q serving "$work/daemon.log" && break; sleep 0.1; done
grep -q serving "$work/daemon.log" || { echo "FAIL: the daemon did not serve"; cat "$work/daemon.log"; exit 1; }
pid=$(pgrep -P $tracer)  # the daemon: signals go to it, not to strace
"$client" --socket "$work/hapticsimd.sock" --duration 1 > "$work/client.json"
kill -HUP $pid; sleep 0.5
kill -TERM $pid; wait $tracer || { echo "FAIL: the daemon did not stop cleanly"; cat "$work/daemon.log"; exit 1; }
grep -q '"in_contact_periods": [1-9]' "$work/client.json" || { echo "FAIL: no session"; cat "$work/client.json"; exit 1; }

# Where the limits allow real time, the daemon gets it: no refusal in its log.
if [ "$(ulimit -r)" -gt 0 ] && grep -q "real-time settings:" "$work/daemon.log"; then
  echo "FAIL: real time refused although RLIMIT_RTPRIO is $(ulimit -r):"
  grep "real-time settings:" "$work/daemon.log"; exit 1
fi

# "PID name(args" or "PID <... name resumed>": the name of every call the daemon made.
used=$(sed -nE 's/^[0-9]+ +(<\.\.\. )?([a-z0-9_]+)(\(| resumed>).*/\2/p' "$work/trace" | sort -u)
required=(sched_setscheduler mlockall memfd_create 'f\?chown' accept4 sendmsg)
# AddressSanitizer turns mlockall into a no-op that makes no system call.
grep -q __asan_init "$daemon" && required=(sched_setscheduler memfd_create 'f\?chown' accept4 sendmsg)
for call in "${required[@]}"; do
  echo "$used" | grep -qx "$call" ||
    { echo "FAIL: no $call traced: the run did not exercise what the filter must allow"; exit 1; }
done
outside=$(comm -23 <(echo "$used") <(allowed_by "$unit"))
# strace itself starts the program with execve: the filter applies after systemd's own exec.
outside=$(echo "$outside" | grep -vx 'execve' || true)
if [ -n "$outside" ]; then
  echo "FAIL: the daemon calls what SystemCallFilter= does not allow: $outside"; exit 1
fi
# A filter without @resources (real time) and @network-io must be caught.
sed 's/^SystemCallFilter=.*/SystemCallFilter=@basic-io @file-system @io-event @process @signal/' \
  "$unit" > "$work/narrow.service"
if [ -z "$(comm -23 <(echo "$used") <(allowed_by "$work/narrow.service"))" ]; then
  echo "FAIL: a narrow filter allowed every call: this check proves nothing"; exit 1
fi
echo "PASS: $(echo "$used" | wc -l) distinct system calls, all in the unit's SystemCallFilter" \
  "(real time $( [ "$(ulimit -r)" -gt 0 ] && echo granted || echo "not available here"))"
