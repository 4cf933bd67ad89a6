#!/usr/bin/env bash
# apt_ensure.sh NAME PACKAGE...: installs the Debian packages of PACKAGE... that are missing.
# Idempotent. As root it installs what is missing, waiting while another apt or dpkg holds the
# package manager (apt_get.sh); otherwise it prints the command and exits 0 (the tests that need
# them then skip locally and fail under CI=true). NAME prefixes the lines.
set -euo pipefail

name=$1
shift
packages=("$@")

missing=()
for pkg in "${packages[@]}"; do
  status=$(dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null || true)
  [ "$status" = "install ok installed" ] || missing+=("$pkg")
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "$name: all packages present (${packages[*]})"
  exit 0
fi

if [ "$(id -u)" != 0 ]; then
  echo "$name: missing packages: ${missing[*]}"
  echo "$name: install them with: sudo apt-get install -y ${missing[*]}"
  exit 0
fi

echo "$name: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
apt_get=$(dirname "$0")/apt_get.sh
bash "$apt_get" update
bash "$apt_get" install -y --no-install-recommends "${missing[@]}"
