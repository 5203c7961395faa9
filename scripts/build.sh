#!/usr/bin/env bash
# Builds the package in a catkin workspace at .ws/ (git-ignored) next to the sources.
# Usage: scripts/build.sh [extra catkin_make arguments]
set -euo pipefail
repo="$(cd "$(dirname "$0")/.." && pwd)"
ws="$repo/.ws"
mkdir -p "$ws/src"
ln -sfn "$repo" "$ws/src/serial_robot_driver"
# catkin needs Debian's python3 (with the ROS modules), not another python3 earlier on PATH.
export PATH="/usr/bin:$PATH"
# catkin caches the environment its run_tests targets use at the first configure, with only the
# paths that exist then: without this folder a fresh workspace's Python rostests could not import
# the package's own messages.
mkdir -p "$ws/devel/lib/python3/dist-packages"
cd "$ws"
catkin_make -DPYTHON_EXECUTABLE=/usr/bin/python3 -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCATKIN_ENABLE_TESTING=ON "$@"
