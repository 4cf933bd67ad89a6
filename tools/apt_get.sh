#!/usr/bin/env bash
# apt_get.sh ARGS...: apt-get ARGS..., once no other package manager holds apt's or dpkg's locks.
#
# A fresh Ubuntu runs unattended-upgrades at boot, and a user may have an install running: a
# bare apt-get then fails at once ("Could not get lock /var/lib/dpkg/lock-frontend"). This
# says who holds the lock and waits for it, APT_LOCK_WAIT seconds at most in all (600 by
# default), then fails naming the holder. apt-get's own DPkg::Lock::Timeout covers dpkg's
# locks only, not the lists lock of `apt-get update`; a lock taken again between the check and
# apt-get is caught by apt-get's message and waited for like the first.
set -uo pipefail

wait_at_most=${APT_LOCK_WAIT:-600}
deadline=$((SECONDS + wait_at_most))
locks='/var/lib/dpkg/lock(-frontend)?$|/var/lib/apt/lists/lock$|/var/cache/apt/archives/lock$'
out=$(mktemp)
trap 'rm -f "$out"' EXIT

holders() {  # "PID COMMAND PATH" of each process holding one of the locks (lslocks: util-linux)
  lslocks -n -o PID,COMMAND,PATH 2>/dev/null | grep -E "$locks" | tr -s ' '
}

said=""
while :; do
  held=$(holders)
  if [ -z "$held" ]; then
    apt-get -o DPkg::Lock::Timeout=$((deadline > SECONDS ? deadline - SECONDS : 0)) "$@" 2>&1 \
      | tee "$out"
    status=${PIPESTATUS[0]}
    grep -q "Could not get lock" "$out" || exit "$status"
    held=$(grep -m1 -o "Could not get lock.*" "$out")
  fi
  if [ "$SECONDS" -ge "$deadline" ]; then
    echo "apt_get: the package manager is still busy after ${wait_at_most} s ($held);" \
      "run the set-up again when it is done, or set APT_LOCK_WAIT to wait longer" >&2
    exit 1
  fi
  if [ "$held" != "$said" ]; then
    echo "apt_get: another package manager holds its lock (${held//$'\n'/; });" \
      "waiting for it, at most $((deadline - SECONDS)) s more"
    said=$held
  fi
  sleep 2
done
