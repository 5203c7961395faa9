#!/usr/bin/env bash
# catkin build (catkin_tools), the other build tool the README promises next to catkin_make: builds
# and installs the package once in a workspace of its own (outside the repository, see
# scratch_dir.sh; kept between runs, so a second run only rebuilds what changed), then runs sim.launch from that
# install space alone and checks that joint_states flow and the servo/ping service is up.
# Tests are not built here (scripts/build.sh's workspace runs them); ccache is used when present.
# Usage: scripts/test_catkin_build.sh [--build-only] [extra cmake arguments]. Prints "catkin build
# test passed" or what failed. --build-only stops after the build (.ci/run builds with it at the
# lowest priority while the tests run, then runs the check with the same cmake arguments).
set -euo pipefail
build_only=false
if [ "${1:-}" = --build-only ]; then build_only=true; shift; fi
repo="$(cd "$(dirname "$0")/.." && pwd)"
source "$repo/scripts/scratch_dir.sh"
ws="${SRD_CATKIN_TOOLS_WS:-$(scratch_dir "$repo" catkin_tools)}"
rm -rf "$repo/.ws_catkin_tools"  # where earlier versions kept it: rosrun would find its copies
export PATH="/usr/bin:/bin"
set -m
# stop_group, run, wait_for
source "$repo/scripts/install_space_support.sh"
started_pids=""
cleanup() { for pid in $started_pids; do stop_group "$pid"; done; }
trap cleanup EXIT
fail() { echo "catkin build test FAILED: $*"; exit 1; }

# SRD_CATKIN_TOOLS_SPACES_IN=<folder>: the source and build spaces go there instead (.ci/run gives
# .ws/, so that ccache serves this build from build.sh's: scripts/shared_ccache.sh).
spaces="${SRD_CATKIN_TOOLS_SPACES_IN:-$ws}"
source_space="$spaces/src" build_space="$spaces/build"
if [ -n "${SRD_CATKIN_TOOLS_SPACES_IN:-}" ]; then
  source_space="$spaces/catkin_tools_src" build_space="$spaces/catkin_tools_build"
fi
mkdir -p "$source_space" "$ws"
ln -sfn "$repo" "$source_space/serial_robot_driver"
cd "$ws"
cmake_args=(-DPYTHON_EXECUTABLE=/usr/bin/python3 -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCATKIN_ENABLE_TESTING=OFF)
if command -v ccache >/dev/null; then cmake_args+=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
cmake_args+=("$@")
[ -d .catkin_tools ] || catkin init > /dev/null
catkin config --install --source-space "$source_space" --build-space "$build_space" \
  --cmake-args "${cmake_args[@]}" > /dev/null
catkin build --no-status --no-notify -j2 serial_robot_driver > "$ws/build.log" 2>&1 ||
  { tail -n 40 "$ws/build.log"; fail "catkin build"; }

install="$ws/install"
[ -x "$install/lib/serial_robot_driver/driver_node" ] || fail "no driver_node in $install"
[ -f "$install/share/serial_robot_driver/launch/sim.launch" ] || fail "no sim.launch in $install"
if [ "$build_only" = true ]; then echo "catkin build done"; exit 0; fi

# The install space alone (with the system's ROS), as in scripts/test_install.sh.
install_prefix="$install"
install_home="$ws/home"
mkdir -p "$install_home"
[ "$(run 'rospack find serial_robot_driver')" = "$install/share/serial_robot_driver" ] ||
  fail "rospack does not find the package in $install"

start_roscore "$ws/roscore.log" || fail "roscore did not start"
link="$ws/sim_pty"
run "exec roslaunch serial_robot_driver sim.launch link:=$link" > "$ws/sim.log" 2>&1 &
started_pids="$! $started_pids"
wait_for 60 'rosservice list | grep -q "^/servo/ping$"' ||
  { tail -n 30 "$ws/sim.log"; fail "sim.launch: no /servo/ping"; }
wait_for 30 'timeout 10 rostopic echo -n 1 --noarr /joint_states | grep -q "^---$"' ||
  { tail -n 30 "$ws/sim.log"; fail "sim.launch: no joint_states"; }
echo "catkin build test passed"
