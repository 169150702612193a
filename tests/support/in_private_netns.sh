#!/usr/bin/env bash
# Runs a command in a private network namespace of its own (user + network namespace, no root
# needed): only a loopback interface, up, with a multicast route on it, so LCM's default udpm://
# transport works and nothing it sends can leave the namespace.
# Usage: in_private_netns.sh [--keep-users] COMMAND [ARGS...]
#   --keep-users: when run by root, a network namespace only, without the user namespace, so the
#   command keeps the machine's users and can become another one (the security tests do).
set -euo pipefail
user_namespace=(--user --map-root-user)
if [ "${1:-}" = "--keep-users" ]; then
  shift
  [ "$(id -u)" -eq 0 ] && user_namespace=()
fi
exec unshare "${user_namespace[@]}" --net sh -c \
  'ip link set lo up && ip route add 224.0.0.0/4 dev lo src 127.0.0.1 && exec "$@"' sh "$@"
