#!/usr/bin/env bash
# Installs the Debian packages that building needs (as root; see apt_ensure.sh): CMake and a
# C/C++ compiler for the interface packages of interfaces/ (tools/setup_interfaces.sh; Ninja
# when present, else make), and the C compiler that builds the optional native extension.
# This is all `make demo` installs from Debian; `make setup` adds the test peer's and the
# fuzzers' packages (setup_peer.sh, setup_fuzz.sh).
set -euo pipefail

exec bash "$(dirname "$0")/apt_ensure.sh" setup_build cmake ninja-build g++
