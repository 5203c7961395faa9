#!/usr/bin/env bash
# How often roscpp loses a service call on a busy machine (bench/service_call_loss.cpp): a private
# roscore, one server, a CPU hog per core plus one, then four clients at once of each way to
# connect (a new connection per call as rosservice makes, a persistent client made per call as the
# tests' callService does, one persistent client kept), ROUNDS rounds of CALLS calls per client.
# About 3 minutes with the defaults. Numbers only.
#
# usage: bench/service_call_loss.sh [ROUNDS (2)] [CALLS per client and round (3000)]
# The executable comes from the clone's .ws/ (built with -DSRD_BUILD_BENCHMARKS=ON) or SRD_BENCH_WS.
set -euo pipefail
export PATH="/usr/bin:$PATH"  # Debian's python3 for roscore

rounds=${1:-2}
calls=${2:-3000}
package_dir=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
ws=${SRD_BENCH_WS:-${package_dir}/.ws}
program="${ws}/devel/lib/serial_robot_driver/service_call_loss"
[[ -x "${program}" ]] || { echo "no ${program}: build with -DSRD_BUILD_BENCHMARKS=ON" >&2; exit 1; }

source "${package_dir}/scripts/free_port.sh"
port=$(free_port)
export ROS_MASTER_URI="http://127.0.0.1:${port}" ROS_HOME
ROS_HOME=$(mktemp -d)
pids=()
cleanup() {
  for pid in "${pids[@]}"; do kill "${pid}" 2>/dev/null || true; done
  wait 2>/dev/null || true
  rm -rf "${ROS_HOME}"
}
trap cleanup EXIT

roscore -p "${port}" >/dev/null 2>&1 &
pids+=($!)
"${program}" --server >/dev/null 2>&1 &
pids+=($!)
until rosservice list 2>/dev/null | grep -q "^/call_loss$"; do sleep 0.5; done
for _ in $(seq $(($(nproc) + 1))); do
  sh -c 'while :; do :; done' &
  pids+=($!)
done

# A client whose call never returns (roscpp has no call time-out) is stopped after hang_s and
# counted as hung; its calls are left out of the sums.
hang_s=$((calls / 10 + 60))
client() {
  timeout "${hang_s}" "${program}" --client "$1" "${calls}" 2>/dev/null || echo "hung"
}
echo "| way to connect | calls | lost | one in | clients hung |"
echo "|---|---|---|---|---|"
for mode in new fresh kept; do
  total=0
  lost=0
  hung=0
  for _ in $(seq "${rounds}"); do
    out=$(for _ in 1 2 3 4; do client "${mode}" & done; wait)
    hung=$((hung + $(grep -c "^hung" <<<"${out}" || true)))
    while read -r _ n _ of _; do
      lost=$((lost + n))
      total=$((total + of))
    done < <(grep "^${mode}: " <<<"${out}" || true)
  done
  one_in=$( ((lost > 0)) && echo $((total / lost)) || echo "none lost")
  echo "| ${mode} | ${total} | ${lost} | ${one_in} | ${hung} |"
done
