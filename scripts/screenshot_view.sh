#!/usr/bin/env bash
# Remakes the pictures in docs/images/: starts a launch file with rviz on a virtual display
# (Xvfb, software OpenGL), drives the simulated robot for a few seconds so odom leaves a trail,
# and saves a screenshot of the display.
#   scripts/screenshot_view.sh                 # view.launch  -> docs/images/view.png
#   scripts/screenshot_view.sh fleet            # fleet_sim.launch rviz:=true -> docs/images/fleet.png
#   scripts/screenshot_view.sh view OUT.png
# Needs the built workspace (.ws, or WS=path), Xvfb and ImageMagick's `import` (the dev-only
# packages of scripts/install_deps.sh --dev). Runs its own roscore on a free port.
set -euo pipefail
repo="$(cd "$(dirname "$0")/.." && pwd)"
scene="${1:-view}"
out="${2:-$repo/docs/images/$scene.png}"
export PATH="/usr/bin:/bin:$PATH"
for tool in Xvfb import roscore; do
  command -v "$tool" > /dev/null || { echo "screenshot: $tool not found (scripts/install_deps.sh --dev)"; exit 1; }
done
# shellcheck disable=SC1091
set +u; source "${WS:-$repo/.ws}/devel/setup.bash"; set -u

work="$(mktemp -d /tmp/srd_screenshot.XXXXXX)"
set -m  # each background job in a process group of its own, stopped with its children
started=""
cleanup() {
  for pid in $started; do
    kill -INT -- "-$pid" 2>/dev/null || continue
    for _ in $(seq 20); do kill -0 -- "-$pid" 2>/dev/null || break; sleep 0.5; done
    kill -KILL -- "-$pid" 2>/dev/null || true
  done
  rm -rf "$work"
}
trap cleanup EXIT
start() { "$@" > "$work/$(basename "$1").$RANDOM.log" 2>&1 & started="$! $started"; }

display=":$((50 + RANDOM % 400))"
start Xvfb "$display" -screen 0 1100x720x24 -nolisten tcp
export DISPLAY="$display" LIBGL_ALWAYS_SOFTWARE=1
source "$repo/scripts/free_port.sh"
export ROS_MASTER_URI="http://localhost:$(free_port)" ROS_HOME="$work/ros"
start roscore -p "${ROS_MASTER_URI##*:}"
for _ in $(seq 60); do rostopic list > /dev/null 2>&1 && break; sleep 0.5; done

case "$scene" in
  view)
    start roslaunch serial_robot_driver view.launch link:="$work/pty" imu_xyz:="0.08 0 0.19"
    drive_ns=("")
    ;;
  fleet)
    start roslaunch serial_robot_driver fleet_sim.launch rviz:=true link_prefix:="$work/pty_"
    drive_ns=(/robot1 /robot2)
    ;;
  *) echo "screenshot: unknown scene '$scene' (view, fleet)"; exit 2 ;;
esac

# Wait for the driver(s), then drive an arc and raise the body joints for the picture.
launch_pid="${started%% *}"
for _ in $(seq 120); do
  kill -0 "$launch_pid" 2> /dev/null || { tail -n 20 "$work"/roslaunch.*.log; echo "screenshot: roslaunch ended"; exit 1; }
  [ "$(rostopic list 2>/dev/null | grep -c "/odom$")" -ge "${#drive_ns[@]}" ] && break
  sleep 0.5
done
sleep 5  # rviz loads the model
turn=0.6
for ns in "${drive_ns[@]}"; do
  start rostopic pub -r 10 "$ns/cmd_vel" geometry_msgs/Twist "{linear: {x: 0.25}, angular: {z: $turn}}"
  turn="-$turn"  # the second robot turns the other way
  start rostopic pub -r 5 "$ns/joint_commands" sensor_msgs/JointState \
    '{name: [joint_1, joint_2], position: [0.6, -0.6]}'
done
sleep 8
mkdir -p "$(dirname "$out")"
import -display "$display" -window root "$out"
echo "saved $out"
