#!/usr/bin/env bash
# Sets up, builds, and runs the whole test suite (GoogleTest through CTest), then the sanitizer
# stages: the threaded tests under ThreadSanitizer, the rest under AddressSanitizer +
# UndefinedBehaviorSanitizer, and every fuzz target for a bounded time (docs/reliability.md).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$root/scripts/build.sh"
(cd "$root/build" && ctest --output-on-failure -j"$(nproc)")

echo
echo "== ThreadSanitizer: the threaded tests (build-tsan/)"
# ThreadSanitizer's build never leaves this machine: built for its CPU (-DHAPTICSIM_NATIVE=ON).
cmake -S "$root" -B "$root/build-tsan" -G Ninja -DHAPTICSIM_SANITIZE=thread -DHAPTICSIM_NATIVE=ON \
  >/dev/null
cmake --build "$root/build-tsan" --target hapticsim_thread_tests
(cd "$root/build-tsan" && ctest -L threads --output-on-failure)

echo
echo "== AddressSanitizer + UndefinedBehaviorSanitizer: the suite (build-asan/, clang)"
# clang: it builds the sanitized suite in about a third of g++'s time here, and its UBSan has no
# vptr bug. -O1 with line tables: fast, and reports still name file and line. Left out: what
# measures real time or runs for minutes (threads: TSan's above; soak; stress; timing: the
# daemon's end-to-end tests, which time 1 kHz answers), since a sanitized step is slower than its
# period; the MPI sweep (Open MPI's own allocations read as leaks); and two physics sweeps that
# run for more than a minute each sanitized (free decay of every paper configuration, 90 s each
# in Release; the sharded sweep), covered by the Release run.
# The portable baseline without dispatch (none under a sanitizer): the kernels' x86-64-v2 code,
# which the Release build above never runs on a CPU with AVX2, is tested here.
# No benchmarks: no test runs them, and a sanitized one measures the sanitizer.
CC=clang CXX=clang++ cmake -S "$root" -B "$root/build-asan" -G Ninja \
  -DHAPTICSIM_SANITIZE=address,undefined -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DHAPTICSIM_BUILD_BENCHMARKS=OFF \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1" >/dev/null
cmake --build "$root/build-asan"
(cd "$root/build-asan" && ctest --output-on-failure -j"$(nproc)" -LE 'threads|soak|stress|timing|mpi' \
  -E 'PoissonRatios/PredictionAgreesWithFreeDecay|ErrorMapCli.ShardsMergeToTheSameResultsAsOneSweep')

echo
echo "== Fuzzing: every target for 20 s (build-fuzz/, clang libFuzzer + ASan + UBSan)"
"$root/scripts/fuzz.sh" --seconds 20
