#!/bin/sh
# Runs a command inside a private network namespace whose only interface is loopback (up), so
# GigE Vision discovery broadcasts and streams never leave the machine. Exit 77 (ctest SKIP) with
# one line when the namespace cannot be created or the fake GigE camera is not installed.
#   run_in_netns.sh <test binary> [args...]
if ! command -v arv-fake-gv-camera-0.8 >/dev/null 2>&1; then
  echo "SKIP: arv-fake-gv-camera-0.8 not found (Debian package aravis-tools)"
  exit 77
fi
if ! unshare -n true 2>/dev/null; then
  echo "SKIP: 'unshare -n' not permitted here (needs root or unprivileged user namespaces); the GigE fake-camera tests need a private network namespace"
  exit 77
fi
exec unshare -n sh -c 'ip link set lo up && exec "$0" "$@"' "$@"
