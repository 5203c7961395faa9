#!/usr/bin/env bash
# Profiles driver_node in the configuration users run (the defaults: base, body and servo bus on
# one port, odom and /tf, diagnostics, battery poll; 20 body servos streaming at 100 Hz) against
# robot_sim, with the subscribers a user has (joint_states, wheel_states, imu/data, odom, /tf,
# /diagnostics, as robot_state_publisher, joint_state_publisher, rviz, the navigation stack and
# diagnostic_aggregator would subscribe; here `rostopic hz`). Prints, per thread of the node: its
# role, its CPU (s/s, from /proc), its CPU per event (telemetry frame, loop tick, ...), its top
# items and (perf) its wake-ups and system calls per second. docs/performance.md explains the
# output; paste it there as is.
#
# usage: scripts/profile_node.sh [--seconds S] [--tool perf|callgrind] [--floor] [--cmd-vel]
#                                [--no-interface] [--out DIR] [--top N]
#   --seconds S   the profiled window (default 30; callgrind: default 20, the node runs ~50x slower)
#   --tool        perf (default when `perf` runs) or callgrind (valgrind; instruction counts of the
#                 window alone, per thread and per event: telemetry frame, loop tick, cmd_vel)
#   --floor       profile the same-job floor instead (bench/floor_node.cpp ~same_job, built with
#                 -DSRD_BUILD_BENCHMARKS=ON), the same way, to compare item by item; with
#                 ~same_interface (the rest of driver_node's interface offered, as driver_bench's
#                 same-job floor) unless --no-interface
#   --cmd-vel     also publish cmd_vel at 20 Hz (off by default, as in the benchmark's CPU window)
#   --out DIR     keep the data, logs and report there (default: a new /tmp/srd_profile_XXXXXX)
#   --top N       items per thread (default 8)
#   SRD_BENCH_WS  the catkin workspace holding driver_node and robot_sim (default: the clone's
#                 .ws/, built by scripts/build.sh; else the sourced one)
#
# Needs (installs nothing): a built driver_node and robot_sim; ROS (roscore, rosparam, rostopic);
# perf (Debian: `apt-get install linux-perf`; perf_event_paranoid <= 1 or root) or valgrind
# (`apt-get install valgrind`, with callgrind_annotate).
set -euo pipefail
export PATH="/usr/bin:$PATH"  # Debian's python3 for the ROS tools

script_dir=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
package_dir=$(cd "${script_dir}/.." && pwd)
seconds=""
tool=""
out=""
top=8
program=driver_node
cmd_vel=0
same_interface=true
while (($#)); do
  case "$1" in
    --seconds) seconds="$2"; shift 2 ;;
    --tool) tool="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --top) top="$2"; shift 2 ;;
    --floor) program=floor_node; shift ;;
    --no-interface) same_interface=false; shift ;;
    --cmd-vel) cmd_vel=1; shift ;;
    -h | --help) sed -n '2,28p' "$0"; exit 0 ;;
    *) echo "profile_node.sh: unknown argument $1 (see --help)" >&2; exit 2 ;;
  esac
done

need() {  # need <command> <what to install>
  command -v "$1" >/dev/null || { echo "profile_node.sh: needs $1 ($2)" >&2; exit 2; }
}
if [[ -z "${tool}" ]]; then
  if command -v perf >/dev/null && perf stat -e cpu-clock true >/dev/null 2>&1; then
    tool=perf
  else
    tool=callgrind
  fi
fi
case "${tool}" in
  perf) need perf "apt-get install linux-perf; and perf_event_paranoid <= 1 or root" ;;
  callgrind)
    need valgrind "apt-get install valgrind"
    need callgrind_annotate "apt-get install valgrind"
    ;;
  *) echo "profile_node.sh: --tool perf or callgrind" >&2; exit 2 ;;
esac
[[ -n "${seconds}" ]] || { [[ "${tool}" == perf ]] && seconds=30 || seconds=20; }

ws="${SRD_BENCH_WS:-}"
if [[ -z "${ws}" && -x "${package_dir}/.ws/devel/lib/serial_robot_driver/driver_node" ]]; then
  ws="${package_dir}/.ws"
fi
load_workspace() {  # a function, so setup.bash does not see this script's arguments
  set +u  # ROS's setup scripts read unset variables
  # shellcheck disable=SC1091
  if [[ -n "${ws}" ]]; then source "${ws}/devel/setup.bash"; fi
  set -u
}
load_workspace
need roscore "ROS (scripts/install_deps.sh)"
need rostopic "ROS (scripts/install_deps.sh)"
bin=""
if [[ -n "${ws}" ]]; then bin="${ws}/devel/lib/serial_robot_driver"; fi
if [[ -z "${bin}" || ! -x "${bin}/driver_node" ]]; then
  bin=$(dirname "$(catkin_find --first-only serial_robot_driver driver_node 2>/dev/null)" || true)
fi
for needed in "${program}" robot_sim; do
  [[ -x "${bin}/${needed}" ]] || {
    echo "profile_node.sh: ${needed} not found: run scripts/build.sh (or set SRD_BENCH_WS)" >&2
    exit 2
  }
done

out="${out:-$(mktemp -d /tmp/srd_profile_XXXXXX)}"
mkdir -p "${out}"
export ROS_LOG_DIR="${out}/ros_log" ROS_HOME="${out}"
port=$(python3 -c 'import socket; s=socket.socket(); s.bind(("",0)); print(s.getsockname()[1])')
export ROS_MASTER_URI="http://localhost:${port}"

pids=()
cleanup() {  # only what this script started, by pid, newest first
  local i
  for ((i = ${#pids[@]} - 1; i >= 0; i--)); do kill -INT "${pids[i]}" 2>/dev/null || true; done
  sleep 1
  for ((i = ${#pids[@]} - 1; i >= 0; i--)); do kill -KILL "${pids[i]}" 2>/dev/null || true; done
}
trap cleanup EXIT
start() {  # start <log> <command...>: in the background, remembered for cleanup
  local log="$1"
  shift
  "$@" >"${out}/${log}.log" 2>&1 &
  pids+=($!)
}

servos=20
ids=$(seq -s, 1 "${servos}")
names=$(seq -f 'joint_%g' -s, 1 "${servos}")
zeros=$(printf '2048,%.0s' $(seq "${servos}"))
ones=$(printf '1,%.0s' $(seq "${servos}"))
pty="${out}/robot.pty"
cat >"${out}/params.yaml" <<EOF
port: ${pty}
same_job: true  # floor_node's (driver_node ignores it)
same_job_statuses: 5  # and key/values: as many as driver_node's here
same_job_values: 97
same_interface: ${same_interface}
body:
  servo_ids: [${ids}]
  joint_names: [${names}]
  zero_ticks: [${zeros%,}]
  directions: [${ones%,}]
EOF

start roscore roscore -p "${port}"
for _ in $(seq 100); do rostopic list >/dev/null 2>&1 && break; sleep 0.2; done
start robot_sim "${bin}/robot_sim" --link "${pty}" --servo-ids "${ids}" --telemetry-rate 100
for _ in $(seq 100); do [[ -e "${pty}" ]] && break; sleep 0.1; done
rosparam load "${out}/params.yaml" /profile/driver
node_args=(__name:=driver __ns:=/profile)
if [[ "${tool}" == callgrind ]]; then
  # Counting starts after the warm-up (callgrind_control -i on): start-up is not in the figures.
  start node valgrind --tool=callgrind --separate-threads=yes --instr-atstart=no \
    --callgrind-out-file="${out}/callgrind.out.%p" "${bin}/${program}" "${node_args[@]}"
else
  start node "${bin}/${program}" "${node_args[@]}"
fi
node_pid=${pids[-1]}
for topic in /profile/joint_states /profile/wheel_states /profile/imu/data /profile/odom /tf \
  /diagnostics; do
  start "hz_$(echo "${topic}" | tr / _)" rostopic hz "${topic}"
done
if ((cmd_vel)); then  # each is written at once by the thread that receives it
  start cmd_vel rostopic pub -r 20 /profile/cmd_vel geometry_msgs/Twist \
    '{linear: {x: 0.1}, angular: {z: 0.2}}'
fi
echo "profile_node.sh: ${tool}, warming up 8 s; then ${seconds} s profiled; output in ${out}" >&2
sleep 8

# CPU time of each thread of the node so far, in ns (schedstat: its first field): "tid ns" lines.
thread_cpu_ns() {
  local stat tid
  for stat in /proc/"${node_pid}"/task/*/schedstat; do
    tid=${stat%/schedstat}
    tid=${tid##*/}
    awk -v tid="${tid}" '{ print tid, $1 }' "${stat}" 2>/dev/null || true
  done
}
# Voluntary and involuntary context switches of each thread: "tid voluntary involuntary" lines.
thread_switches() {
  local status tid
  for status in /proc/"${node_pid}"/task/*/status; do
    tid=${status%/status}
    tid=${tid##*/}
    awk -v tid="${tid}" '/^voluntary_ctxt_switches/ { v = $2 }
      /^nonvoluntary_ctxt_switches/ { n = $2 } END { print tid, v, n }' "${status}" 2>/dev/null ||
      true
  done
}
# The CPU per thread from a window of its own: perf's sampling (stacks copied in the kernel) is
# charged to the threads it samples. Callgrind's whole run is slow anyway: one window.
if [[ "${tool}" == callgrind ]]; then callgrind_control -i on "${node_pid}" >/dev/null; fi
thread_cpu_ns >"${out}/cpu_ns_start"
thread_switches >"${out}/switches_start"
sleep "${seconds}"
thread_cpu_ns >"${out}/cpu_ns_end"
thread_switches >"${out}/switches_end"
if [[ "${tool}" == perf ]]; then
  echo "profile_node.sh: CPU window done; perf records ${seconds} s more" >&2
  # The system calls each thread makes, counted alongside (perf record's sampling slows the
  # threads, not the number of calls they make).
  syscalls=$(printf 'syscalls:sys_enter_%s,' read write poll ppoll sendto recvfrom futex \
    epoll_wait epoll_ctl clock_nanosleep)
  perf stat --per-thread -x, -e "${syscalls%,}" -p "${node_pid}" -o "${out}/syscalls.csv" \
    -- sleep "${seconds}" >/dev/null 2>&1 &
  syscall_counter=$!
  perf record -e cpu-clock -F 4999 --call-graph dwarf,8192 -p "${node_pid}" -o "${out}/perf.data" \
    -- sleep "${seconds}" >"${out}/perf_record.log" 2>&1
  wait "${syscall_counter}" || true
fi
if [[ "${tool}" == callgrind ]]; then
  # The window's counts in their own files (callgrind.out.<pid>.1-<thread>); exit adds none.
  callgrind_control -i off "${node_pid}" >/dev/null
  callgrind_control -d "${node_pid}" >/dev/null
  kill -INT "${node_pid}"
  wait "${node_pid}" || true
fi

python3 "${script_dir}/profile_report.py" "${tool}" "${out}" "${seconds}" "${top}" "${program}" |
  tee "${out}/report.md"
