#!/bin/sh
# Runs a command in a private network namespace that has only the loopback
# interface, with the multicast route LCM needs (deps.md): loopback tests then
# neither hear nor disturb anything else on the host, and need no network.
# Where no namespace can be made (no user namespaces, no `ip`), the command
# runs on the host network; the tests still use their own LCM ports and DDS
# domains.
if command -v unshare >/dev/null 2>&1 && command -v ip >/dev/null 2>&1 &&
   unshare -rn sh -c 'ip link set lo up' >/dev/null 2>&1; then
  exec unshare -rn sh -c 'ip link set lo up && ip route add 224.0.0.0/4 dev lo && exec "$@"' run_isolated "$@"
fi
echo "run_isolated.sh: no private network namespace here; using the host network" >&2
exec "$@"
