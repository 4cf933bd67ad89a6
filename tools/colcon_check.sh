#!/usr/bin/env bash
# Build this repository as a ROS package, the way users do: the repository in a colcon
# workspace's src/, `colcon build`, then `ros2 run ros_gz_bridge_py parameter_bridge`.
#
# colcon comes from PyPI (pinned below) into a throwaway venv under .build/colcon/ that is
# reused while the pins stay the same; the workspace is made anew on every run from a copy of
# the sources (so the build cannot write into the repository). Checks: the console scripts are
# where `ros2 run` looks (install/<pkg>/lib/<pkg>/), the ament index marker, package.xml, the
# launch files, the launch examples and their configurations are installed, and the installed
# package (not the repository's) imports and runs.
#
# Exit status: 0 ok, 1 a check failed, 3 colcon could not be installed (e.g. no registry).
set -euo pipefail

ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
PKG=ros_gz_bridge_py
BASE=${COLCON_CHECK_DIR:-$ROOT/.build/colcon}
VENV=$BASE/venv
WS=$BASE/ws
# The Python that runs the installed package afterwards (it has protobuf & co).
PROJECT_PYTHON=${PROJECT_PYTHON:-$ROOT/.venv/bin/python}
# setuptools: Ubuntu 24.04's (Jazzy's) python3-setuptools, the oldest a colcon user has; it cannot
# read an SPDX `license` string in pyproject.toml (setup.cfg holds the license instead).
PINS=(
  colcon-core==0.21.3
  colcon-ros==0.5.0
  colcon-python-setup-py==0.2.9
  colcon-library-path==0.2.1
  colcon-recursive-crawl==0.2.3
  colcon-package-selection==0.2.10
  colcon-parallel-executor==0.4.0
  catkin-pkg==1.1.1
  setuptools==68.1.2
)

fail() {
  echo "colcon_check: FAILED: $*" >&2
  exit 1
}

install_colcon() {
  local stamp=$VENV/.pins
  if [[ -x $VENV/bin/colcon && -f $stamp && "$(cat "$stamp")" == "${PINS[*]}" ]]; then
    return 0
  fi
  rm -rf "$VENV"
  mkdir -p "$BASE"
  if ! python3 -m venv "$VENV" ||
    ! "$VENV/bin/pip" install --quiet --disable-pip-version-check "${PINS[@]}" >"$BASE/pip.log" 2>&1; then
    echo "colcon_check: cannot install colcon (see $BASE/pip.log)" >&2
    rm -rf "$VENV"
    exit 3
  fi
  echo "${PINS[*]}" >"$stamp"
}

copy_sources() {
  rm -rf "$WS"
  mkdir -p "$WS/src/$PKG"
  tar -C "$ROOT" -cf - \
    --exclude=./.venv --exclude=./.build --exclude=./.git --exclude=./build \
    --exclude='*.egg-info' --exclude=__pycache__ --exclude='.*_cache' . |
    tar -C "$WS/src/$PKG" -xf -
}

build() {
  echo "colcon_check: colcon build in $WS"
  if ! (cd "$WS" && COLCON_HOME=$BASE/colcon-home "$VENV/bin/colcon" build \
    --event-handlers console_direct+ >"$WS/build.log" 2>&1); then
    cat "$WS/build.log" >&2
    fail "colcon build (log above)"
  fi
}

check_install() {
  local prefix=$WS/install/$PKG
  for script in parameter_bridge bridge_node image_bridge bridge_types; do
    [[ -x $prefix/lib/$PKG/$script ]] || fail "missing executable lib/$PKG/$script"
  done
  [[ -f $prefix/share/ament_index/resource_index/packages/$PKG ]] ||
    fail "missing ament index marker share/ament_index/resource_index/packages/$PKG"
  [[ -f $prefix/share/$PKG/package.xml ]] || fail "missing share/$PKG/package.xml"
  # ros_gz_bridge's launch files (launch/); the launch examples find their configurations
  # relative to the package root.
  local src=$WS/src/$PKG data
  for data in "$src"/launch/ros_gz_bridge.launch* "$src"/launch_examples/*.launch.py \
    "$src"/launch_examples/config/*.yaml "$src"/config/*.yaml; do
    data=${data#"$src"/}
    [[ -f $prefix/share/$PKG/$data ]] || fail "missing share/$PKG/$data"
  done
  if [[ ! -x $PROJECT_PYTHON ]]; then
    echo "colcon_check: $PROJECT_PYTHON not found; not running the installed scripts"
    return 0
  fi
  local site
  site=$(echo "$prefix"/lib/python3*/site-packages)
  local origin
  origin=$(cd "$WS" && PYTHONPATH=$site "$PROJECT_PYTHON" -c "import $PKG; print($PKG.__file__)")
  [[ $origin == "$site/"* ]] || fail "imported $origin instead of the installed package"
  local answer
  answer=$(cd "$WS" && PYTHONPATH=$site "$PROJECT_PYTHON" "$prefix/lib/$PKG/bridge_types" \
    --get-ros-to-gz std_msgs/msg/String)
  [[ $answer == gz.msgs.StringMsg ]] || fail "installed bridge_types answered '$answer'"
}

install_colcon
copy_sources
build
check_install
echo "colcon_check: OK ($WS/install/$PKG/lib/$PKG/parameter_bridge)"
