#!/usr/bin/env bash
# Installs the Debian packages the native transcoder's fuzz target needs (tests/unit/native/
# test_fuzz.py, `make fuzz`): clang-14 and its sanitizer and libFuzzer runtimes.
# Idempotent. As root it installs what is missing; otherwise it prints the command and
# exits 0 (the fuzz test then skips locally and fails under CI=true).
set -euo pipefail

packages=(clang-14 libclang-rt-14-dev)

missing=()
for pkg in "${packages[@]}"; do
  status=$(dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null || true)
  [ "$status" = "install ok installed" ] || missing+=("$pkg")
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup_fuzz: all packages present (${packages[*]})"
  exit 0
fi

if [ "$(id -u)" != 0 ]; then
  echo "setup_fuzz: missing packages: ${missing[*]}"
  echo "setup_fuzz: install them with: sudo apt-get install -y ${missing[*]}"
  exit 0
fi

echo "setup_fuzz: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
apt-get update
apt-get install -y --no-install-recommends "${missing[@]}"
