#!/usr/bin/env bash
# The main job on a fresh machine: install, build, then run driver_node against robot_sim
# (launch/sim.launch). Extra arguments go to roslaunch, e.g. garbage_rate:=5 unplug_every:=10.
set -euo pipefail
repo="$(cd "$(dirname "$0")/.." && pwd)"
bash "$repo/scripts/install_deps.sh"
bash "$repo/scripts/build.sh" -j2 >/dev/null
set +u
source "$repo/.ws/devel/setup.bash"
set -u
exec roslaunch serial_robot_driver sim.launch "$@"
