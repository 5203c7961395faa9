#!/usr/bin/env bash
# catkin build (catkin_tools), the other build tool the README promises next to catkin_make: builds
# and installs the package once in a workspace of its own (.ws_catkin_tools/, git-ignored; kept
# between runs, so a second run only rebuilds what changed), then runs sim.launch from that
# install space alone and checks that joint_states flow and the servo/ping service is up.
# Tests are not built here (scripts/build.sh's workspace runs them); ccache is used when present.
# Usage: scripts/test_catkin_build.sh. Prints "catkin build test passed" or what failed.
set -euo pipefail
repo="$(cd "$(dirname "$0")/.." && pwd)"
ws="${SRD_CATKIN_TOOLS_WS:-$repo/.ws_catkin_tools}"
export PATH="/usr/bin:/bin"
set -m
stop_group() {  # SIGINT to a job's process group, SIGKILL after 10 s
  kill -INT -- "-$1" 2>/dev/null || return 0
  for _ in $(seq 20); do kill -0 -- "-$1" 2>/dev/null || return 0; sleep 0.5; done
  kill -KILL -- "-$1" 2>/dev/null || true
}
started_pids=""
cleanup() { for pid in $started_pids; do stop_group "$pid"; done; }
trap cleanup EXIT
fail() { echo "catkin build test FAILED: $*"; exit 1; }

mkdir -p "$ws/src"
ln -sfn "$repo" "$ws/src/serial_robot_driver"
cd "$ws"
cmake_args=(-DPYTHON_EXECUTABLE=/usr/bin/python3 -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCATKIN_ENABLE_TESTING=OFF)
if command -v ccache >/dev/null; then cmake_args+=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
[ -d .catkin_tools ] || catkin init > /dev/null
catkin config --install --cmake-args "${cmake_args[@]}" > /dev/null
catkin build --no-status --no-notify -j2 serial_robot_driver > "$ws/build.log" 2>&1 ||
  { tail -n 40 "$ws/build.log"; fail "catkin build"; }

install="$ws/install"
[ -x "$install/lib/serial_robot_driver/driver_node" ] || fail "no driver_node in $install"
[ -f "$install/share/serial_robot_driver/launch/sim.launch" ] || fail "no sim.launch in $install"

# The install space alone (with the system's ROS), as in scripts/test_install.sh.
master_port=$((20000 + RANDOM % 20000))
home="$ws/home"
mkdir -p "$home"
run() {
  env -i HOME="$home" PATH="/usr/bin:/bin" ROS_HOME="$home/.ros" \
    ROS_MASTER_URI="http://localhost:$master_port" CMAKE_PREFIX_PATH="$install" \
    ROS_PACKAGE_PATH="$install/share" LD_LIBRARY_PATH="$install/lib" \
    PYTHONPATH="$(ls -d "$install"/lib/python3*/dist-packages 2>/dev/null | head -n 1)" \
    bash -c "$1"
}
wait_for() {  # wait_for <seconds> <command run in the install environment>
  local deadline=$((SECONDS + $1))
  until run "$2" > /dev/null 2>&1; do
    [ $SECONDS -lt $deadline ] || return 1
    sleep 1
  done
}
[ "$(run 'rospack find serial_robot_driver')" = "$install/share/serial_robot_driver" ] ||
  fail "rospack does not find the package in $install"

run "exec roscore -p $master_port" > "$ws/roscore.log" 2>&1 &
started_pids="$! $started_pids"
wait_for 30 'rostopic list' || fail "roscore did not start"
link="$ws/sim_pty"
run "exec roslaunch serial_robot_driver sim.launch link:=$link" > "$ws/sim.log" 2>&1 &
started_pids="$! $started_pids"
wait_for 60 'rosservice list | grep -q "^/servo/ping$"' ||
  { tail -n 30 "$ws/sim.log"; fail "sim.launch: no /servo/ping"; }
wait_for 30 'timeout 10 rostopic echo -n 1 --noarr /joint_states | grep -q "^---$"' ||
  { tail -n 30 "$ws/sim.log"; fail "sim.launch: no joint_states"; }
echo "catkin build test passed"
