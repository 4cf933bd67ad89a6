#!/usr/bin/env bash
# Installs the Debian packages the native transcoders' fuzz targets need (tests/unit/native/
# test_fuzz.py, `make fuzz`): clang-14 and its sanitizer and libFuzzer runtimes (as root; see
# apt_ensure.sh).
set -euo pipefail

exec bash "$(dirname "$0")/apt_ensure.sh" setup_fuzz clang-14 libclang-rt-14-dev
