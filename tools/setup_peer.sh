#!/usr/bin/env bash
# Installs the Debian packages the real-Gazebo interop tests need: the Ignition Transport 11
# CLI tools and the headers/libraries our C++ test peer (tests/peer) builds against.
# Idempotent. As root it installs what is missing; otherwise it prints the command and
# exits 0 (the peer tests then skip locally and fail under CI=true).
# The `ign` Ruby wrapper (ignition-tools, ruby) is not needed: tests call
# /usr/libexec/ignition/transport11/ign-transport-{topic,service} directly.
set -euo pipefail

packages=(ignition-transport-cli libignition-transport-dev libignition-msgs-dev
          protobuf-compiler cmake ninja-build g++)

missing=()
for pkg in "${packages[@]}"; do
  status=$(dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null || true)
  [ "$status" = "install ok installed" ] || missing+=("$pkg")
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup_peer: all packages present (${packages[*]})"
  exit 0
fi

if [ "$(id -u)" != 0 ]; then
  echo "setup_peer: missing packages: ${missing[*]}"
  echo "setup_peer: install them with: sudo apt-get install -y ${missing[*]}"
  exit 0
fi

echo "setup_peer: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
apt-get update
apt-get install -y --no-install-recommends "${missing[@]}"
