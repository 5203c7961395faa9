#!/usr/bin/env bash
# Runs the driver_node benchmarks (bench/driver_bench.cpp): a private roscore, driver_node and
# robot_sim over pseudo-terminals, about 3 minutes. Prints a table and writes it to
# bench/results/latest.md (or $SRD_BENCH_OUTPUT).
#
# usage: bench/run_benchmarks.sh [--build] [--long] [driver_bench options, see --help]
#   --build             catkin_make driver_bench (and driver_node, robot_sim, floor_node) first,
#                       -j2, with -DSRD_BUILD_BENCHMARKS=ON (benchmarks are off by default)
#   --long              longer runs (about 15 minutes); also SRD_BENCH_LONG=1
#   SRD_BENCH_WS=DIR    the catkin workspace to use (default: the sourced one, or the one this
#                       script was installed into)
set -euo pipefail
export PATH="/usr/bin:$PATH"  # Debian's python3 for the ROS tools

script_dir=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
package_dir=$(cd "${script_dir}/.." && pwd)

build=0
args=()
for arg in "$@"; do
  case "${arg}" in
    --build) build=1 ;;
    *) args+=("${arg}") ;;
  esac
done
if [[ "${SRD_BENCH_LONG:-0}" == "1" ]]; then args+=(--long); fi

if [[ -n "${SRD_BENCH_WS:-}" ]]; then
  if (( build )); then
    (cd "${SRD_BENCH_WS}" && catkin_make -DPYTHON_EXECUTABLE=/usr/bin/python3 -DSRD_BUILD_BENCHMARKS=ON --make-args -j2 driver_bench)
  fi
  load_workspace() {  # a function, so setup.bash does not see this script's arguments
    set +u  # ROS's setup scripts read unset variables
    # shellcheck disable=SC1091
    source "${SRD_BENCH_WS}/devel/setup.bash"
    set -u
  }
  load_workspace
  bench="${SRD_BENCH_WS}/devel/lib/serial_robot_driver/driver_bench"
elif command -v catkin_find >/dev/null && [[ -n "${ROS_PACKAGE_PATH:-}" ]]; then
  bench=$(catkin_find --first-only serial_robot_driver driver_bench 2>/dev/null || true)
else
  bench=""
fi
if [[ -z "${bench}" || ! -x "${bench}" ]]; then
  echo "run_benchmarks.sh: driver_bench not found. Build it (catkin_make driver_bench) and set" \
       "SRD_BENCH_WS=<workspace>, or source the workspace's setup.bash." >&2
  exit 2
fi

if [[ -n "${SRD_BENCH_OUTPUT:-}" ]]; then
  output="${SRD_BENCH_OUTPUT}"
elif [[ -w "${package_dir}" && -d "${package_dir}/bench" ]]; then
  output="${package_dir}/bench/results/latest.md"
else
  output="${PWD}/driver_bench_latest.md"
fi
mkdir -p "$(dirname "${output}")"

# driver_bench cleans up its roscore and nodes on SIGINT/SIGTERM; forward ours to it.
"${bench}" --output "${output}" "${args[@]}" &
bench_pid=$!
trap 'kill -TERM "${bench_pid}" 2>/dev/null || true' INT TERM
status=0
wait "${bench_pid}" || status=$?
# A signal interrupts the first wait; wait again for the cleanup to finish.
if kill -0 "${bench_pid}" 2>/dev/null; then wait "${bench_pid}" || status=$?; fi
exit "${status}"
