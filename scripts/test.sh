#!/usr/bin/env bash
# Sets up, builds, and runs the whole test suite (GoogleTest through CTest), then the threaded
# tests again under ThreadSanitizer.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$root/scripts/build.sh"
(cd "$root/build" && ctest --output-on-failure -j"$(nproc)")

echo
echo "== ThreadSanitizer: the threaded tests (build-tsan/)"
cmake -S "$root" -B "$root/build-tsan" -G Ninja -DHAPTICSIM_SANITIZE=thread >/dev/null
cmake --build "$root/build-tsan" --target hapticsim_thread_tests
(cd "$root/build-tsan" && ctest -L threads --output-on-failure)
