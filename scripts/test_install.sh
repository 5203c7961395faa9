#!/usr/bin/env bash
# Install-space test: installs the built workspace (.ws/build by default) into a temporary prefix,
# then, in an environment that holds only the system's ROS and that prefix (no devel space, no
# source tree), checks that a user gets what they need and nothing they should not:
#   - executables, libsrd_nodelet, launch/, config/ (parameters, analyzers, udev rule), msg/srv,
#     the nodelet plugin description, srd_core's headers; no srd_ros/srd_sim headers, no benchmarks;
#   - rospack finds the package and its nodelet plugin; every launch file passes roslaunch's check;
#   - sim.launch runs (joint_states flow, the servo/ping service exists), `rostopic echo` prints a
#     message of every topic the node publishes and every service's type loads (the Python message
#     packages of install_deps.sh), description.launch puts the robot's links on /tf,
#     fleet_sim.launch runs two robots under their prefixes, and driver.launch nodelet:=true
#     loads serial_robot_driver/DriverNodelet against robot_sim.
# Usage: scripts/test_install.sh [build dir]. Prints "install test passed" or what failed.
set -euo pipefail
repo="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:-$repo/.ws/build}"
export PATH="/usr/bin:/bin"
prefix="$(mktemp -d /tmp/srd_install.XXXXXX)"
# Job control: each background job gets a process group of its own (so its children can be
# stopped with it) and keeps SIGINT, which a non-interactive shell would otherwise ignore.
set -m
# stop_group, run, wait_for
source "$repo/scripts/install_space_support.sh"
cleanup() {
  # Only the process groups this script started, never by name; the newest first.
  for pid in ${started_pids:-}; do stop_group "$pid"; done
  [ -n "${KEEP_INSTALL:-}" ] || rm -rf "$prefix"
}
trap cleanup EXIT
started_pids=""

fail() { echo "install test FAILED: $*"; exit 1; }

cmake --install "$build" --prefix "$prefix" > "$prefix.install.log" 2>&1 ||
  { tail -n 20 "$prefix.install.log"; fail "cmake --install"; }
rm -f "$prefix.install.log"

share="$prefix/share/serial_robot_driver"
for f in lib/serial_robot_driver/driver_node lib/serial_robot_driver/robot_sim lib/libsrd_nodelet.so \
         lib/serial_robot_driver/robot_description lib/serial_robot_driver/calibrate_base \
         share/serial_robot_driver/launch/description.launch \
         share/serial_robot_driver/launch/view.launch share/serial_robot_driver/config/view.rviz \
         share/serial_robot_driver/launch/fleet_sim.launch share/serial_robot_driver/config/fleet.rviz \
         lib/libsrd_core.a share/serial_robot_driver/package.xml \
         share/serial_robot_driver/nodelet_plugins.xml share/serial_robot_driver/launch/driver.launch \
         share/serial_robot_driver/launch/sim.launch share/serial_robot_driver/launch/record.launch \
         share/serial_robot_driver/config/robot.yaml share/serial_robot_driver/config/analyzers.yaml \
         share/serial_robot_driver/config/99-serial-robot.rules \
         share/serial_robot_driver/msg/Telemetry.msg share/serial_robot_driver/srv/ServoPing.srv \
         include/serial_robot_driver/devices/base/base_codec.h include/serial_robot_driver/Telemetry.h; do
  [ -e "$prefix/$f" ] || fail "missing $f"
done
for f in include/serial_robot_driver/ros include/serial_robot_driver/sim \
         include/serial_robot_driver/devices/base/ros/base_ros.h \
         include/serial_robot_driver/devices/base/sim/base_sim.h \
         lib/serial_robot_driver/driver_bench lib/serial_robot_driver/polling_driver_node \
         lib/serial_robot_driver/bench_framer lib/serial_robot_driver/run_benchmarks.sh; do
  [ ! -e "$prefix/$f" ] || fail "$f is installed but should not be"
done

# Everything below runs with the install space alone.
install_prefix="$prefix"
install_home="$prefix/home"
mkdir -p "$prefix/home"

[ "$(run 'rospack find serial_robot_driver')" = "$share" ] || fail "rospack does not find $share"
run 'rospack plugins --attrib=plugin nodelet' | grep -q "^serial_robot_driver $share/nodelet_plugins.xml" ||
  fail "the nodelet plugin description is not exported"
run 'rosmsg show serial_robot_driver/Telemetry' | grep -q servo_ids || fail "rosmsg show Telemetry"
run 'rossrv show serial_robot_driver/ServoPing' | grep -q id || fail "rossrv show ServoPing"
# Unset required args (replay.launch's bag) are the user's to give, as in the build's launch check.
# One Python process checks every launch file (an interpreter start is about a second).
cat > "$prefix/check_launch.py" <<'PY'
import sys
import roslaunch.rlutil as rlutil
errors = [(f, rlutil.check_roslaunch(f, ignore_unset_args=True)) for f in sys.argv[1:]]
for launch, error in errors:
    if error:
        print("roslaunch check of %s: %s" % (launch, error))
sys.exit(1 if any(error for _, error in errors) else 0)
PY
out="$(run "python3 $prefix/check_launch.py $share/launch/*.launch" 2>&1)" || fail "$out"

start_roscore "$prefix/roscore.log" || fail "roscore did not start"

link="$prefix/sim_pty"
# capture, foot and polled servo angles: serial_raw, foot_pressure and servo_states flow too, so
# every topic can be echoed. (The later servo_bus mapping replaces robot.yaml's; its other keys
# take the node's defaults.)
{ cat "$share/config/robot.yaml"; printf 'servo_bus:\n  state_ids: [1]\n'; } > "$prefix/all_topics.yaml"
run "exec roslaunch serial_robot_driver sim.launch link:=$link capture:=true foot:=true config:=$prefix/all_topics.yaml" > "$prefix/sim.log" 2>&1 &
started_pids="$! $started_pids"
sim_launch=$!
wait_for 60 'rosservice list | grep -q "^/servo/ping$"' ||
  { tail -n 30 "$prefix/sim.log"; fail "sim.launch: no /servo/ping"; }
wait_for 30 'timeout 6 rostopic bw -w 3 /joint_states 2>&1 | grep -q average' ||
  { tail -n 30 "$prefix/sim.log"; fail "sim.launch: no joint_states"; }

# description.launch next to it: the robot's links on /tf (the wheels need wheel_states merged).
run "exec roslaunch serial_robot_driver description.launch" > "$prefix/description.log" 2>&1 &
started_pids="$! $started_pids"
description_launch=$!
wait_for 60 'timeout 10 rostopic echo -n 50 /tf 2>&1 | grep -q "child_frame_id: \"left_wheel_link\""' ||
  { tail -n 30 "$prefix/description.log"; fail "description.launch: no left_wheel_link on /tf"; }
stop_group "$description_launch"
# `rostopic echo` of every topic the node publishes (a moving base: wheel_command flows), and the
# request type of every service it serves, with the Python message classes the set-up installs.
run "exec rostopic pub -r 10 /cmd_vel geometry_msgs/Twist '{linear: {x: 0.1}}'" > "$prefix/cmd_vel.log" 2>&1 &
started_pids="$! $started_pids"
cmd_vel_pub=$!
node_info="$(run 'rosnode info /driver_node 2>/dev/null')"
publications="$(echo "$node_info" | sed -n '/^Publications:/,/^$/p' | sed -nE 's/^ \* ([^ ]+) .*/\1/p' | grep -v '^/rosout$')"
services="$(echo "$node_info" | sed -n '/^Services:/,/^$/p' | sed -nE 's/^ \* ([^ ]+).*/\1/p' | grep -vE '/(get_loggers|set_logger_level)$')"
[ "$(echo "$publications" | wc -w)" -ge 10 ] || fail "rosnode info lists too few publications: $publications"
# The echoes run side by side, each into a file of its own (each waits up to a second for its
# topic's next message); the services' request types load in one Python process, with
# rosservice's own functions behind `rosservice args` and `rosservice type`.
echo_pids=()
echo_topics=()
for topic in $publications; do
  case "$topic" in
    # An action's feedback and result flow only while a goal runs (trajectory.test covers them):
    # here their Python message classes must load, which is what `rostopic echo` needs.
    */feedback|*/result)
      type="$(run "rostopic type $topic")"
      run "python3 -c 'import ${type%%/*}.msg as m; m.${type##*/}'" ||
        fail "the Python message class of $topic ($type) does not load"
      echo "loaded $type"
      continue ;;
  esac
  run "timeout 20 rostopic echo -n 1 --noarr $topic" > "$prefix/echo.${#echo_pids[@]}" 2>&1 &
  echo_pids+=($!)
  echo_topics+=("$topic")
done
for i in "${!echo_pids[@]}"; do
  topic="${echo_topics[$i]}"
  out="$prefix/echo.$i"
  wait "${echo_pids[$i]}" || fail "rostopic echo $topic: $(tail -n 3 "$out")"
  grep -q "^---$" "$out" || fail "rostopic echo $topic printed no message: $(tail -n 3 "$out")"
  echo "echoed $topic"
done
cat > "$prefix/check_services.py" <<'PY'
import sys
import rosservice
for name in sys.argv[1:]:
    rosservice.get_service_args(name)  # loads the request class, as `rosservice args` does
    print("service %s: %s" % (name, rosservice.get_service_type(name)))
PY
out="$(run "python3 $prefix/check_services.py $(echo $services)" 2>&1)" ||
  fail "a service's request type does not load: $(echo "$out" | tail -n 3)"
echo "$out"
stop_group "$cmd_vel_pub"
stop_group "$sim_launch"

# fleet_sim.launch: two robots in namespaces, each robot's links under its tf_prefix.
run "exec roslaunch serial_robot_driver fleet_sim.launch link_prefix:=$prefix/fleet_" > "$prefix/fleet.log" 2>&1 &
started_pids="$! $started_pids"
fleet_launch=$!
for robot in robot1 robot2; do
  wait_for 60 "rosservice list | grep -q '^/$robot/servo/ping$'" ||
    { tail -n 30 "$prefix/fleet.log"; fail "fleet_sim.launch: no /$robot/servo/ping"; }
  wait_for 60 "timeout 10 rostopic echo -n 50 /tf 2>&1 | grep -q 'child_frame_id: \"$robot/left_wheel_link\"'" ||
    { tail -n 30 "$prefix/fleet.log"; fail "fleet_sim.launch: no $robot/left_wheel_link on /tf"; }
done
stop_group "$fleet_launch"

# The nodelet from the install space: robot_sim alone, and driver.launch nodelet:=true on its pty.
run "exec rosrun serial_robot_driver robot_sim --link $link" > "$prefix/robot_sim.log" 2>&1 &
started_pids="$! $started_pids"
run "exec roslaunch serial_robot_driver driver.launch nodelet:=true port:=$link respawn:=false" \
  > "$prefix/nodelet.log" 2>&1 &
started_pids="$! $started_pids"
wait_for 60 'timeout 6 rostopic bw -w 3 /joint_states 2>&1 | grep -q average' ||
  { tail -n 30 "$prefix/nodelet.log"; fail "driver.launch nodelet:=true: no joint_states"; }
run 'rostopic info /joint_states' | grep -q "/driver_nodelet_manager" ||
  fail "joint_states does not come from the nodelet manager"

echo "install test passed"
