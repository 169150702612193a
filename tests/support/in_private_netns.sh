#!/usr/bin/env bash
# Runs a command in a private network namespace of its own (user + network namespace, no root
# needed): only a loopback interface, up, with a multicast route on it, so LCM's default udpm://
# transport works and nothing it sends can leave the namespace.
# Usage: in_private_netns.sh COMMAND [ARGS...]
set -euo pipefail
exec unshare --user --map-root-user --net sh -c \
  'ip link set lo up && ip route add 224.0.0.0/4 dev lo && exec "$@"' sh "$@"
