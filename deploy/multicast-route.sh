#!/usr/bin/env bash
# LCM's udpm transport needs a route for 224.0.0.0/4. On a host (or network namespace)
# with only the loopback interface there is none and LCM fails with "LCM requires a
# valid multicast route". Add one on lo when root; otherwise print the exact command.
set -u
if ip route get 239.255.76.67 >/dev/null 2>&1; then
  exit 0
fi
if [ "$(id -u)" -eq 0 ]; then
  ip link set lo multicast on 2>/dev/null || true
  if ip route add 224.0.0.0/4 dev lo 2>/dev/null; then
    echo "multicast-route: added 224.0.0.0/4 dev lo"
    exit 0
  fi
fi
echo "multicast-route: no multicast route. Run as root:  ip route add 224.0.0.0/4 dev lo" >&2
exit 1
