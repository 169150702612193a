#!/usr/bin/env bash
# The portable default build (x86-64-v2, kernels chosen at load time) against a native one
# (-march=native), side by side: builds build-native/ (hapticsim only) beside build/, then
# alternates the two binaries round by round, so whatever else the machine does falls on both,
# and prints the medians and the median of the rounds' ratios (portable / native: 1.00 = as
# fast, 1.10 = 10 % slower). Measured: the matrix-free K·u on the 25³ and 49³ grids (`hapticsim
# bench --kernels`), and the cost of one adaptive configuration and its full-resolution
# reference on the 25³ scene (`hapticsim bench`: element loops, fine boxes, the time step).
# Results: docs/benchmarks.md, "Portable build". Takes a build (~10 min on 2 cores) and ~5 min.
# Usage: scripts/bench-portable.sh [ROUNDS=5]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
rounds=${1:-5}
portable=$root/build/tools/hapticsim
native=$root/build-native/tools/hapticsim
[ -x "$portable" ] || { echo "bench-portable: build/ first (scripts/build.sh)"; exit 2; }
grep -q "march=x86-64-v2" "$root/build/compile_commands.json" ||
  { echo "bench-portable: build/ is not the portable default (configure it with -DHAPTICSIM_NATIVE=OFF)"; exit 2; }
cmake -S "$root" -B "$root/build-native" -G Ninja -DHAPTICSIM_NATIVE=ON -DHAPTICSIM_BUILD_TESTS=OFF \
  -DHAPTICSIM_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build "$root/build-native" --target hapticsim
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
scene=(--set mesh.nodes=25 --primary-size 2 --secondary-lod 2 --secondary-rate 1000)
for r in $(seq "$rounds"); do
  for build in portable native; do
    echo "round $r/$rounds: $build" >&2
    "${!build}" bench --kernels --nodes 25,49 --seconds 1 --json > "$work/kernels-$build-$r.json"
    "${!build}" bench "${scene[@]}" --json > "$work/scene-$build-$r.json"
  done
done
python3 - "$work" "$rounds" <<'PY'
import json, statistics, sys
work, rounds = sys.argv[1], int(sys.argv[2])
def load(kind, build, r):
    return json.load(open(f"{work}/{kind}-{build}-{r}.json"))
rows = []  # (what, unit, per-round portable, per-round native)
for i, n in enumerate((25, 49)):
    rows.append((f"K·u matrix-free, {n}³ grid", "µs",
                 [load("kernels", "portable", r)["kernels"][i]["matrix_free_us"] for r in range(1, rounds + 1)],
                 [load("kernels", "native", r)["kernels"][i]["matrix_free_us"] for r in range(1, rounds + 1)]))
def scene_costs(build, r):
    j = load("scene", build, r)
    return j["reference_cost_us_per_ms"], j["configurations"][0]["cost_us_per_ms"]
for k, what in enumerate(("full-resolution reference, 25³ scene", "adaptive configuration 2/2/1000 Hz, 25³ scene")):
    rows.append((what, "µs per simulated ms",
                 [scene_costs("portable", r)[k] for r in range(1, rounds + 1)],
                 [scene_costs("native", r)[k] for r in range(1, rounds + 1)]))
isa = load("kernels", "portable", 1)["kernel_instruction_set"]
print(f"portable build: kernels run with {isa}; native: {load('kernels', 'native', 1)['kernel_instruction_set']}")
print(f"{rounds} alternating rounds; medians, and the median of the rounds' ratios")
print(f"| what | portable | native | portable / native |")
print(f"|---|---|---|---|")
for what, unit, p, n in rows:
    ratio = statistics.median(a / b for a, b in zip(p, n))
    print(f"| {what} | {statistics.median(p):,.1f} {unit} | {statistics.median(n):,.1f} {unit} | {ratio:.3f} |")
PY
