# Helpers of the tests that run the package from an install space alone, with the system's ROS
# (test_install.sh, test_catkin_build.sh). Source it with `set -m` in force; before calling run,
# set install_prefix (the install space) and install_home (a HOME of its own).
# Debian's catkin installs no setup.bash into a prefix; run sets the variables it would set.
source "$(dirname "${BASH_SOURCE[0]}")/free_port.sh"
master_port=""  # start_roscore picks it, just before the master starts

stop_group() {  # SIGINT to a job's process group, SIGKILL after 10 s
  kill -INT -- "-$1" 2>/dev/null || return 0
  for _ in $(seq 20); do kill -0 -- "-$1" 2>/dev/null || return 0; sleep 0.5; done
  kill -KILL -- "-$1" 2>/dev/null || true
}

run() {  # run <command>: in an environment holding only the system's ROS and the install space
  env -i HOME="$install_home" PATH="/usr/bin:/bin" ROS_HOME="$install_home/.ros" \
    ROS_MASTER_URI="http://localhost:$master_port" CMAKE_PREFIX_PATH="$install_prefix" \
    ROS_PACKAGE_PATH="$install_prefix/share" LD_LIBRARY_PATH="$install_prefix/lib" \
    PYTHONPATH="$(ls -d "$install_prefix"/lib/python3*/dist-packages 2>/dev/null | head -n 1)" \
    bash -c "$1"
}

start_roscore() {  # start_roscore <log>: a master on a free port; a port taken meanwhile is retried
  local attempt
  : > "$1"
  for attempt in 1 2 3; do
    master_port=$(free_port)
    run "exec roscore -p $master_port" >> "$1" 2>&1 &
    started_pids="$! ${started_pids:-}"
    wait_for 30 'rostopic list' && return 0
    stop_group "$!"
    echo "roscore did not start on port $master_port (attempt $attempt)" >> "$1"
  done
  tail -n 5 "$1"
  return 1
}

wait_for() {  # wait_for <seconds> <command run in the install environment>
  local deadline=$((SECONDS + $1))
  until run "$2" > /dev/null 2>&1; do
    [ $SECONDS -lt $deadline ] || return 1
    sleep 1
  done
}
