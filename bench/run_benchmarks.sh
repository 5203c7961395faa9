#!/usr/bin/env bash
# Runs the driver_node benchmarks (bench/driver_bench.cpp, a private roscore, the nodes over
# pseudo-terminals). By default section 8 alone, about 8-9 minutes: driver_node in the
# configuration users run (every default device, 20 body servos at 100 Hz, the topics a user
# subscribes) side by side with the floor (bench/floor_node.cpp), quiet and under a CPU hog per
# core, with ~realtime_priority off and on, each figure as node / floor / ratio, the robot played
# over a pty and over loopback TCP (--transport pty|tcp|both; pty alone about 5 minutes; TCP has no
# kernel pty worker in the path: the programs' own latency). --all runs every section (about 12
# minutes; 8 with --transport pty), then the framer's (bench/bench_framer.cpp, Google Benchmark, a
# few seconds) and the cost of waiting per wake-up, the node's way and the floor's
# (bench/bench_wait.cpp, 80 s).
# Prints the tables and writes them to bench/results/user_config.md (section 8 alone) or
# bench/results/latest.md (--all or --sections), or $SRD_BENCH_OUTPUT.
#
# usage: bench/run_benchmarks.sh [--build] [--all] [--long] [driver_bench options, see --help]
#   --all               every section (1-10), bench_framer and bench_wait, instead of section 8 alone
#   --build             build driver_bench (and driver_node, robot_sim, floor_node, servo_floor,
#                       polling_driver_node) first, -j2, with -DSRD_BUILD_BENCHMARKS=ON (benchmarks
#                       are off by default): in SRD_BENCH_WS, or else in the clone's own .ws/ with
#                       scripts/build.sh, so `bench/run_benchmarks.sh --build` works on a fresh clone
#   --long              longer runs (about 15 minutes); also SRD_BENCH_LONG=1
#   --transport T       section 8's line: pty, tcp or both (default both; passed to driver_bench)
#   --dds               instead: dds_bench alone (bench/dds_bench.cpp, built with Cyclone DDS only),
#                       about 2-3 minutes: telemetry -> joint_states over DDS (p50/p99) and the CPU of
#                       driver_node with ~ros2/enabled on and off and of dds_driver, alternating
#                       rounds; its table goes to bench/results/dds.md (or $SRD_BENCH_OUTPUT)
#   SRD_BENCH_WS=DIR    the catkin workspace to use (default: the clone's .ws/ when it holds
#                       driver_bench or --build is given, else the sourced one)
set -euo pipefail
export PATH="/usr/bin:$PATH"  # Debian's python3 for the ROS tools

script_dir=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
package_dir=$(cd "${script_dir}/.." && pwd)

build=0
all=0
dds=0
sections_given=0
args=()
for arg in "$@"; do
  case "${arg}" in
    --build) build=1 ;;
    --all) all=1 ;;
    --dds) dds=1 ;;
    --sections) sections_given=1; args+=("${arg}") ;;
    *) args+=("${arg}") ;;
  esac
done
if (( ! all && ! sections_given && ! dds )); then args+=(--sections 8); fi
if [[ "${SRD_BENCH_LONG:-0}" == "1" ]]; then args+=(--long); fi

own_ws="${package_dir}/.ws"
if [[ -z "${SRD_BENCH_WS:-}" && -f "${package_dir}/scripts/build.sh" ]]; then
  if (( build )) || [[ -x "${own_ws}/devel/lib/serial_robot_driver/driver_bench" ]]; then
    SRD_BENCH_WS="${own_ws}"
  fi
fi
# ccache, when installed, makes a rebuild on a fresh clone mostly cache hits.
launcher=()
if command -v ccache >/dev/null; then launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi

if [[ -n "${SRD_BENCH_WS:-}" ]]; then
  if (( build )); then
    if [[ "${SRD_BENCH_WS}" == "${own_ws}" ]]; then
      bash "${package_dir}/scripts/build.sh" -DSRD_BUILD_BENCHMARKS=ON "${launcher[@]}" -j2 driver_bench
    else
      (cd "${SRD_BENCH_WS}" && catkin_make -DPYTHON_EXECUTABLE=/usr/bin/python3 -DSRD_BUILD_BENCHMARKS=ON "${launcher[@]}" --make-args -j2 driver_bench)
    fi
    if (( dds )); then (cd "${SRD_BENCH_WS}/build" && make -j2 dds_bench); fi
    (cd "${SRD_BENCH_WS}/build" && make -j2 bench_wait)
    # bench_framer exists only where Google Benchmark is installed (libbenchmark-dev).
    (cd "${SRD_BENCH_WS}/build" && make -j2 bench_framer) ||
      echo "run_benchmarks.sh: bench_framer not built (no Google Benchmark); its section is skipped" >&2
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
  echo "run_benchmarks.sh: driver_bench not found. Run bench/run_benchmarks.sh --build (builds it" \
       "in ${own_ws}), or set SRD_BENCH_WS=<workspace> where it is built." >&2
  exit 2
fi

# --dds: the ROS 2 front end's benchmark alone (it starts its own roscore and cleans up on SIGINT).
if (( dds )); then
  dds_bench="$(dirname "${bench}")/dds_bench"
  if [[ ! -x "${dds_bench}" ]]; then
    echo "run_benchmarks.sh: ${dds_bench} not built (it needs Cyclone DDS: scripts/install_deps.sh;" \
         "then --build --dds)" >&2
    exit 2
  fi
  output="${SRD_BENCH_OUTPUT:-${package_dir}/bench/results/dds.md}"
  mkdir -p "$(dirname "${output}")"
  exec "${dds_bench}" --output "${output}" "${args[@]}"
fi

if [[ -n "${SRD_BENCH_OUTPUT:-}" ]]; then
  output="${SRD_BENCH_OUTPUT}"
elif [[ -w "${package_dir}" && -d "${package_dir}/bench" ]]; then
  output="${package_dir}/bench/results/latest.md"
  if (( ! all && ! sections_given )); then output="${package_dir}/bench/results/user_config.md"; fi
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
# The framer's throughput (Google Benchmark), appended to the same file, when it is built.
framer="$(dirname "${bench}")/bench_framer"
if [[ "${status}" -eq 0 && "${all}" -eq 1 && -x "${framer}" ]]; then
  framer_out=$(mktemp)
  "${framer}" --benchmark_min_time=0.2 | tee "${framer_out}"
  {
    echo
    echo "### Framer and decoders (bench_framer, Google Benchmark, 0.2 s per benchmark)"
    echo
    echo '```'
    cat "${framer_out}"
    echo '```'
  } >> "${output}"
  rm -f "${framer_out}"
fi
# What the node's reader and loop spend to wait their (wakeable) way, against the floor's.
waiter="$(dirname "${bench}")/bench_wait"
if [[ "${status}" -eq 0 && "${all}" -eq 1 && -x "${waiter}" ]]; then
  wait_out=$(mktemp)
  "${waiter}" --rounds 4 | tee "${wait_out}"
  {
    echo
    echo "### Waiting for the next event, per wake-up (bench_wait)"
    cat "${wait_out}"
  } >> "${output}"
  rm -f "${wait_out}"
fi
exit "${status}"
