#!/usr/bin/env bash
# Installs the dependencies (scripts/setup.sh) and builds hapticsim into build/ (Release).
# Usage: scripts/build.sh [extra cmake configure arguments]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$root/scripts/setup.sh"
cmake -S "$root" -B "$root/build" -G Ninja "$@" >/dev/null
cmake --build "$root/build"
