#!/usr/bin/env bash
# The stability stress under timing faults as CI runs it: `hapticsim stress --faults` runs every
# case built as production builds regions on real threads with injected secondary lags, stalls
# and late primary wakes; none may diverge, none may end above the energy bound by more than the
# port limits allow, and the faults must really have been injected.
# Usage: stress_faults_test.sh HAPTICSIM COUNT OUT.json
set -euo pipefail
hapticsim=$1 count=$2 out=$3
status=0
"$hapticsim" stress --faults --count "$count" --seed 1 --max-nodes 7 --supervisor-every 1000000 \
  --json > "$out" || status=$?
cat "$out"
if [ "$status" -ne 0 ]; then echo "FAIL: hapticsim stress --faults exited $status"; exit 1; fi
field() { grep -o "\"$1\": [0-9.e+-]*" "$out" | head -1 | awk '{print $2}'; }
runs=$(field fault_runs)
[ -n "$runs" ] && [ "$runs" -ge $((count / 2)) ] ||
  { echo "FAIL: only ${runs:-no} fault runs among $count cases"; exit 1; }
for kind in secondary_lags secondary_stalls primary_late_wakes secondary_skips; do
  value=$(field "$kind")
  if [ -z "$value" ] || [ "$value" = 0 ]; then echo "FAIL: no $kind injected"; exit 1; fi
done
[ "$(field diverged_under_faults)" = 0 ] || { echo "FAIL: a run diverged under faults"; exit 1; }
[ "$(field fault_energy_balance_violations)" = 0 ] ||
  { echo "FAIL: a run under faults ended above the energy bound the port limits guarantee"; exit 1; }
echo "stress --faults: $runs runs under timing faults, none diverged, none above the energy bound"
