#!/usr/bin/env bash
# Sets up, builds, and runs the main job on the built-in default scene:
#  1. the full-resolution reference simulation of the paper's cube
#     (build/forces.csv and build/forces.svg);
#  2. the default scene's error map (build/maps/default-scene.hsmap: every adaptive configuration
#     and input of the paper's grid for the scene's material; made once per hapticsim version,
#     about half a minute on 2 cores), and the error it gives the default adaptive configuration.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
hapticsim="$root/build/tools/hapticsim"
"$root/scripts/build.sh"
echo
"$hapticsim" simulate --out "$root/build/forces.csv" --plot "$root/build/forces.svg"

map="$root/build/maps/default-scene.hsmap"
mkdir -p "$(dirname "$map")"
version="$("$hapticsim" --version)"
if [ ! -f "$map" ] || ! "$hapticsim" map info "$map" --json | grep -qF "\"code_version\": \"$version\""; then
  echo
  echo "Making the default scene's error map (once per hapticsim version): $map"
  "$hapticsim" sweep --grid scene --out "$map"
fi
echo
echo "Error of the adaptive configuration primary_size 3, secondary_lod 2, secondary_rate 600 Hz"
echo "on the default scene (worst force-magnitude error, % of the reference peak; 7 % is the JND):"
"$hapticsim" lookup "$map" --set primary_size=3 --set secondary_lod=2 --set secondary_rate=600
