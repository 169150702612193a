#!/usr/bin/env bash
# Coverage-guided fuzzing of every parser and decoder at a boundary (fuzz/): builds the libFuzzer
# targets with clang, ASan and UBSan into build-fuzz/, then fuzzes each for a while, starting
# from the committed corpus (fuzz/corpus/). A crash, hang or unbounded allocation fails the run
# and leaves its input in build-fuzz/crashes/; copy it to fuzz/reproducers/TARGET/ so the test
# suite replays it from then on.
# Usage: scripts/fuzz.sh [--seconds N] [TARGET...]   (default: 30 s each, every target)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
seconds=30
targets=()
while [ $# -gt 0 ]; do
  case "$1" in
    --seconds) seconds=$2; shift 2 ;;
    -h|--help) sed -n '2,8p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) targets+=("$1"); shift ;;
  esac
done
[ ${#targets[@]} -gt 0 ] || targets=(scene_toml daemon_config error_map lcm_messages shm_segment service_handshake control_line
                                      nifti surface_mesh)

"$root/scripts/setup.sh"
CC=clang CXX=clang++ cmake -S "$root" -B "$root/build-fuzz" -G Ninja -DHAPTICSIM_FUZZ=ON -DHAPTICSIM_NATIVE=ON \
  -DHAPTICSIM_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build "$root/build-fuzz" --target hapticsim_fuzzers

failed=()
for target in "${targets[@]}"; do
  work="$root/build-fuzz/corpus/$target"
  mkdir -p "$work" "$root/build-fuzz/crashes"
  echo "== fuzzing $target for $seconds s"
  # Bounded: 5 s per input is a hang, 1 GiB of RSS or one 256 MiB allocation is unbounded memory.
  log="$root/build-fuzz/$target.log"
  status=0
  "$root/build-fuzz/fuzz/${target}_fuzzer" "$work" "$root/fuzz/corpus/$target" \
    -max_total_time="$seconds" -timeout=5 -rss_limit_mb=1024 -malloc_limit_mb=256 \
    -artifact_prefix="$root/build-fuzz/crashes/$target-" -print_final_stats=1 >"$log" 2>&1 ||
    status=$?
  grep -E "(DONE|==[0-9]+==|SUMMARY|Test unit written|stat::number_of_executed_units|stat::peak_rss_mb)" "$log" || true
  if [ "$status" -ne 0 ]; then
    tail -40 "$log"
    failed+=("$target")
  fi
done
if [ ${#failed[@]} -gt 0 ]; then
  echo "fuzz: FAILED: ${failed[*]} (inputs in build-fuzz/crashes/; add them to fuzz/reproducers/TARGET/)"
  exit 1
fi
echo "fuzz: ${#targets[@]} targets, $seconds s each, no crash, hang or unbounded allocation"
