#!/usr/bin/env bash
# Installs the Debian packages the real-Gazebo interop tests need: the Ignition Transport 11
# CLI tools and the headers/libraries our C++ test peer (testing/peer) builds against (as root;
# see apt_ensure.sh). The `ign` Ruby wrapper (ignition-tools, ruby) is not needed: tests call
# /usr/libexec/ignition/transport11/ign-transport-{topic,service} directly.
set -euo pipefail

exec bash "$(dirname "$0")/apt_ensure.sh" setup_peer \
  ignition-transport-cli libignition-transport-dev libignition-msgs-dev \
  protobuf-compiler cmake ninja-build g++
