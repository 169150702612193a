#!/usr/bin/env bash
# Sets up, builds, and runs the main job on the built-in default scene: the full-resolution
# reference simulation of the paper's cube. Writes build/forces.csv and build/forces.svg.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$root/scripts/build.sh"
echo
"$root/build/tools/hapticsim" simulate --out "$root/build/forces.csv" --plot "$root/build/forces.svg"
