#!/usr/bin/env bash
# Runs a command inside a private network namespace with loopback up, multicast on it and a
# multicast route on lo, so LCM (udpm) and DDS traffic never leaves it (Cyclone DDS and Fast DDS
# discover each other only with lo's multicast flag on). Where namespaces are not permitted: says so, exits 77.
set -u
if ! unshare -n true 2>/dev/null; then
  echo "SKIPPED: cannot create a network namespace here (unshare -n not permitted)"
  exit 77
fi
if ! command -v ip > /dev/null; then
  echo "SKIPPED: ip (iproute2) is not installed; scripts/install_deps.sh installs it"
  exit 77
fi
exec unshare -n bash -c 'ip link set lo up && ip link set lo multicast on && ip route add 224.0.0.0/4 dev lo &&
  MBOT_NETNS=1 exec "$@"' _ "$@"
