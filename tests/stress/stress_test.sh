#!/usr/bin/env bash
# The stability stress test as CI runs it: `hapticsim stress` on small meshes must pass every
# check (exit 0), and the draw must have produced every kind of case, or the checks were vacuous.
# Usage: stress_test.sh HAPTICSIM COUNT OUT.json
set -euo pipefail
hapticsim=$1 count=$2 out=$3
status=0
"$hapticsim" stress --count "$count" --seed 1 --max-nodes 7 --supervisor-every 2 --json > "$out" || status=$?
cat "$out"
if [ "$status" -ne 0 ]; then echo "FAIL: hapticsim stress exited $status"; exit 1; fi
field() { grep -o "\"$1\": [0-9.e+-]*" "$out" | head -1 | awk '{print $2}'; }
[ "$(field count)" = "$count" ] || { echo "FAIL: count is not $count"; exit 1; }
for kind in predicted_stable run_past_limit coupling_only_unstable divergence_detected \
            passive_expected passive_expected_bare_unstable \
            supervisor_choices; do
  value=$(field "$kind")
  if [ -z "$value" ] || [ "$value" = 0 ]; then
    echo "FAIL: no $kind case among $count: the draw no longer covers it"; exit 1
  fi
done
for zero in predicted_stable_diverged energy_balance_violations divergence_undetected \
            passive_expected_diverged \
            supervisor_chose_unstable; do
  [ "$(field "$zero")" = 0 ] || { echo "FAIL: $zero is not 0"; exit 1; }
done
echo "stress: every check passed over $count cases"
