#!/usr/bin/env bash
# Build the ROS interface packages under interfaces/ into a Python venv, once.
#
# usage: tools/setup_interfaces.sh [--check] VENV [PACKAGE...]
#
# For each package (all of interfaces/ by default):
#   * "provided by the environment": importable from VENV's python and not built by this
#     script (a full ROS install, or wheels), so it is left alone;
#   * "up to date": built by this script from sources identical to the current ones;
#   * "built": otherwise it is built with cmake (ninja, else make) against the ros-jazzy-*
#     wheels in VENV and installed into the VENV prefix.
# The packages that need a build are built side by side, ROS_GZ_IFACE_JOBS at a time (default:
# the number of cores). With --check nothing is built: packages that would be are reported as "needs a build",
# and the exit status is 1 if there is any.
# A stamp VENV/share/ros_gz_bridge_py_interfaces/<pkg>.sha256 holds the hash of the sources
# it was built from, and <pkg>.manifest the installed files: after a rebuild, those the new
# build did not install again are removed, so no stale generated file survives (and the
# package stays importable while it is rebuilt). Build trees go to
# ROS_GZ_IFACE_BUILD_DIR (default: <repo>/.build/interfaces/<the venv's folder name>).
set -euo pipefail

# Each depends only on the common interfaces (tf2_msgs also on action_msgs, which
# ros-jazzy-rclpy brings; marine_acoustic_msgs on std_msgs and geometry_msgs), none on another
# package of this list: they build in any order, side by side. `make demo` builds tf2_msgs only
# (its TurtleBot3 configuration needs no other); `make setup` builds them all.
DEFAULT_PACKAGES=(tf2_msgs ros_gz_interfaces vision_msgs gps_msgs actuator_msgs marine_acoustic_msgs)

die() { echo "setup_interfaces: $*" >&2; exit 1; }

CHECK=0
if [ "${1:-}" = --check ]; then CHECK=1; shift; fi
[ $# -ge 1 ] && [ -n "$1" ] || die "usage: $0 [--check] VENV [PACKAGE...] (VENV empty: is \$VIRTUAL_ENV set? activate the venv or give its path)"
VENV=$(realpath "$1"); shift
PY=$VENV/bin/python
[ -x "$PY" ] || die "$PY not found: VENV must be a Python venv with ros-jazzy-rclpy installed"
REPO=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
SRC_ROOT=$REPO/interfaces
BUILD_ROOT=${ROS_GZ_IFACE_BUILD_DIR:-$REPO/.build/interfaces/$(basename "$VENV")}
STAMP_DIR=$VENV/share/ros_gz_bridge_py_interfaces
if [ $# -gt 0 ]; then PACKAGES=("$@"); else PACKAGES=("${DEFAULT_PACKAGES[@]}"); fi

mkdir -p "$STAMP_DIR" "$BUILD_ROOT"
# Two runs on one venv (parallel test sessions) would install over each other.
exec 9>"$STAMP_DIR/.lock"
flock 9

source_hash() {  # hash of every file of a package source tree, names included
  (cd "$1" && find . -type f -print0 | LC_ALL=C sort -z | xargs -0 sha256sum) \
    | sha256sum | cut -d' ' -f1
}

importable() {  # the package imports and the type support of its first message loads
  local first
  first=$(find "$SRC_ROOT/$1/msg" -name '*.msg' | LC_ALL=C sort | head -n1)
  first=$(basename "$first" .msg)
  "$PY" - "$1" "$first" >/dev/null 2>&1 <<'PYEOF'
import importlib
import sys

cls = getattr(importlib.import_module(sys.argv[1] + ".msg"), sys.argv[2])
cls.__class__.__import_type_support__()
PYEOF
}

prepare_build_tools() {  # once per run, only when something has to be built
  local piplog=$BUILD_ROOT/pip.log wheels
  # Build-time wheels: pyproject.toml's `interfaces` extra (tools/requirements.py prints it).
  mapfile -t wheels < <("$PY" "$REPO/tools/requirements.py" --extras-only interfaces)
  if ! "$PY" -m pip install --disable-pip-version-check "${wheels[@]}" >"$piplog" 2>&1; then
    tail -n 20 "$piplog" >&2
    die "pip could not install the build-time wheels into $VENV (log: $piplog)"
  fi
  # The wheels' exported CMake targets name the manylinux build container's include
  # directories; point them at this interpreter's (idempotent: a no-op once rewritten).
  local pyv tag pyinc npinc files
  pyv=$("$PY" -c 'import sys; print(f"{sys.version_info[0]}.{sys.version_info[1]}")')
  tag=cp${pyv/./}-cp${pyv/./}
  pyinc=$("$PY" -c 'import sysconfig; print(sysconfig.get_paths()["include"])')
  npinc=$("$PY" -c 'import numpy; print(numpy.get_include())')
  files=$(grep -rl "/opt/python/$tag/" "$VENV"/share/*/cmake 2>/dev/null || true)
  if [ -n "$files" ]; then
    echo "$files" | xargs sed -i \
      -e "s#/opt/python/$tag/include/python$pyv#$pyinc#g" \
      -e "s#/opt/python/$tag/lib/python$pyv/site-packages/numpy/_core/include#$npinc#g"
  fi
  if command -v ninja >/dev/null; then GENERATOR=Ninja; else GENERATOR="Unix Makefiles"; fi
}

prune_previous_install() {  # files of the previous build that this one did not install again
  local old=$STAMP_DIR/$1.manifest new=$2 f
  [ -f "$old" ] || return 0
  while IFS= read -r f; do
    case "$f" in "$VENV"/*) rm -f -- "$f" ;; *) continue ;; esac
    case "$f" in *.py)  # and the bytecode that importing it left behind
      local stem=${f##*/}
      rm -f -- "${f%/*}/__pycache__/${stem%.py}".*.pyc ;;
    esac
  done < <(LC_ALL=C comm -23 <(LC_ALL=C sort -u "$old") <(LC_ALL=C sort -u "$new"))
}

build_package() {
  local pkg=$1 src=$SRC_ROOT/$1 b=$BUILD_ROOT/$1
  rm -f -- "$STAMP_DIR/$pkg.sha256"
  rm -rf -- "$b"
  mkdir -p "$b"
  local step
  for step in configure build install; do
    local log=$b/$step.log
    if ! (
      cd "$b"
      export PATH=$VENV/bin:$PATH
      case $step in
        configure)
          cmake "$src" -G "$GENERATOR" -DCMAKE_PREFIX_PATH="$VENV" \
            -DCMAKE_INSTALL_PREFIX="$VENV" -DPython3_EXECUTABLE="$PY" \
            -DCMAKE_BUILD_TYPE=Release -DBUILD_TESTING=OFF ;;
        build) cmake --build . -j"$(nproc)" ;;
        install) cmake --install . ;;
      esac
    ) >"$log" 2>&1; then
      tail -n 40 "$log" >&2
      die "$pkg: $step failed (full log: $log)"
    fi
  done
  prune_previous_install "$pkg" "$b/install_manifest.txt"
  cp -- "$b/install_manifest.txt" "$STAMP_DIR/$pkg.manifest"
}

# What needs a build, and the source hash it is built from.
declare -A WANT
TODO=()
for pkg in "${PACKAGES[@]}"; do
  [ -f "$SRC_ROOT/$pkg/package.xml" ] || die "no interface package '$pkg' in $SRC_ROOT"
  want=$(source_hash "$SRC_ROOT/$pkg")
  stamp=$STAMP_DIR/$pkg.sha256
  if [ -f "$stamp" ]; then
    if [ "$(cat "$stamp")" = "$want" ] && importable "$pkg"; then
      echo "$pkg: up to date"
      continue
    fi
  elif [ ! -f "$STAMP_DIR/$pkg.manifest" ] && importable "$pkg"; then
    echo "$pkg: provided by the environment"
    continue
  fi
  if [ "$CHECK" = 1 ]; then
    echo "$pkg: needs a build"
  fi
  WANT[$pkg]=$want
  TODO+=("$pkg")
done
[ "$CHECK" = 1 ] && exit $(( ${#TODO[@]} > 0 ))
[ ${#TODO[@]} -gt 0 ] || exit 0

build_and_stamp() {
  local pkg=$1 start=$SECONDS
  build_package "$pkg"
  importable "$pkg" || die "$pkg: built and installed, but '$PY' cannot import it"
  echo "${WANT[$pkg]}" >"$STAMP_DIR/$pkg.sha256"
  echo "$pkg: built ($((SECONDS - start)) s)"
}

# The packages depend on none of each other: JOBS build side by side (a build's configure step
# and its code generators run on one core, its compiles on all).
JOBS=${ROS_GZ_IFACE_JOBS:-$(nproc)}
prepare_build_tools
echo "building ${TODO[*]} ($JOBS at a time)"
running=0
failed=0
for pkg in "${TODO[@]}"; do
  if [ "$running" -ge "$JOBS" ]; then
    wait -n || failed=1
    running=$((running - 1))
  fi
  build_and_stamp "$pkg" &
  running=$((running + 1))
done
while [ "$running" -gt 0 ]; do
  wait -n || failed=1
  running=$((running - 1))
done
[ "$failed" = 0 ] || die "some packages did not build (above)"
