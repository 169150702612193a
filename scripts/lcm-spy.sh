#!/usr/bin/env bash
# Opens lcm-spy on hapticsimd's channels with the hapticsim types decoded.
# Usage: scripts/lcm-spy.sh [LCM_URL]   (default: the daemon's, udpm://239.255.76.67:7667?ttl=0)
# Needs a display (or Xvfb). Uses the jar the build makes (build/lcmtypes/hapticsim-lcmtypes.jar)
# and calls Java directly: the shipped lcm-spy script passes -Xincgc, which Java 17 refuses, and
# the message viewer needs jchart2d on the class path (libjchart2d-java).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
url="${1:-${LCM_DEFAULT_URL:-udpm://239.255.76.67:7667?ttl=0}}"
types="$root/build/lcmtypes/hapticsim-lcmtypes.jar"
[ -f "$types" ] || { echo "lcm-spy.sh: $types is missing: build first (scripts/build.sh)" >&2; exit 2; }
classpath="/usr/share/java/lcm.jar:$types"
[ -f /usr/share/java/jchart2d.jar ] && classpath="$classpath:/usr/share/java/jchart2d.jar"
exec java -cp "$classpath" lcm.spy.Spy --lcm-url="$url"
