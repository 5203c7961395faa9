#!/usr/bin/env bash
# Traces where a frame waits with ~realtime_priority on under a CPU hog: runs driver_bench's
# section 8 in that one condition (bench/run_benchmarks.sh --conditions load_rt) and records the
# kernel's scheduler events (sched_waking, sched_wakeup, sched_switch, sched_migrate_task, in a
# tracefs instance of its own) for TRACE_SECONDS of the program's streaming and cmd_vel windows,
# then prints per 50 Hz tick timer -> loop runs -> write() -> pty kworker runs -> benchmark's
# reader woken, and the waits of the loop and reader threads while another thread of the same
# process held a core (scripts/realtime_trace.py). docs/performance.md ("With
# ~realtime_priority") explains the output.
#
# usage: scripts/trace_realtime.sh [--program driver_node|floor_node] [--out DIR]
#                                  [run_benchmarks.sh options, e.g. --bin-dir DIR]
#   --program  the program traced (default driver_node; floor_node: the same-job floor)
#   --out DIR  keep the trace there (default: a new /tmp/srd_rt_trace_XXXXXX)
#   TRACE_SECONDS  the traced window (default 12), from 8 s after the program starts
#
# Needs root (tracefs at /sys/kernel/tracing, mounted here if it is not) and a driver_bench built
# (bench/run_benchmarks.sh --build).
set -euo pipefail
script_dir=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
package_dir=$(cd "${script_dir}/.." && pwd)
program=driver_node
out=""
bench_args=()
while (($#)); do
  case "$1" in
    --program) program="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    *) bench_args+=("$1"); shift ;;
  esac
done
[[ -n "${out}" ]] || out=$(mktemp -d /tmp/srd_rt_trace_XXXXXX)
mkdir -p "${out}"
# driver_bench names each session's namespace user_<variant>_load_rt_r<round> (with _tcp over TCP).
case "${program}" in
  driver_node) namespace="__ns:=/user_event_load_rt" ;;
  floor_node) namespace="__ns:=/user_floorjob_load_rt" ;;
  *) echo "trace_realtime.sh: --program driver_node or floor_node" >&2; exit 2 ;;
esac

tracing=/sys/kernel/tracing
[[ -d "${tracing}/instances" ]] || mount -t tracefs nodev "${tracing}"
instance="${tracing}/instances/srd_rt_trace_$$"
mkdir "${instance}"
events=(sched/sched_switch sched/sched_wakeup sched/sched_waking sched/sched_migrate_task)
cleanup() { rmdir "${instance}" 2>/dev/null || true; }
trap cleanup EXIT
echo 40000 >"${instance}/buffer_size_kb"
for event in "${events[@]}"; do echo 1 >"${instance}/events/${event}/enable"; done
echo 0 >"${instance}/tracing_on"

# Over the pty (the kernel's pty worker is what this traces) unless --transport tcp is given.
SRD_BENCH_OUTPUT="${out}/bench.md" bash "${package_dir}/bench/run_benchmarks.sh" --conditions load_rt --transport pty "${bench_args[@]}" \
  >"${out}/bench.log" 2>&1 &
bench_pid=$!
# Whether process $1 descends from process $2 (other sessions may run the same benchmark).
descends_from() {
  local process=$1
  while [[ -n "${process}" && "${process}" -gt 1 ]]; do
    [[ "${process}" == "$2" ]] && return 0
    process=$(awk '{print $4}' "/proc/${process}/stat" 2>/dev/null || true)
  done
  return 1
}
pid=""
while [[ -z "${pid}" ]] && kill -0 "${bench_pid}" 2>/dev/null; do
  for candidate in $(pgrep -x "${program}" || true); do
    if tr '\0' ' ' <"/proc/${candidate}/cmdline" | grep -q -- "${namespace}" &&
      descends_from "${candidate}" "${bench_pid}"; then pid=${candidate}; fi
  done
  sleep 0.2
done
[[ -n "${pid}" ]] || { echo "trace_realtime.sh: ${program} never ran; see ${out}/bench.log" >&2; exit 1; }
sleep 8
# Each thread of the traced process: id, name, policy and priority as /proc/<tid>/sched holds them.
for task in "/proc/${pid}/task/"*; do
  echo "$(basename "${task}") $(cat "${task}/comm") $(grep -E '^(policy|prio) ' "${task}/sched" | tr -s ' ' | tr '\n' ' ')"
done >"${out}/threads"
echo 1 >"${instance}/tracing_on"
sleep "${TRACE_SECONDS:-12}"
echo 0 >"${instance}/tracing_on"
cat "${instance}/trace" >"${out}/trace"
for event in "${events[@]}"; do echo 0 >"${instance}/events/${event}/enable"; done
wait "${bench_pid}" || true
grep -E '\| on ' "${out}/bench.log" | grep -E 'joint_states p99|jitter|worst period' || true
python3 "${script_dir}/realtime_trace.py" "${out}/trace" "${out}/threads"
echo "trace, threads and the benchmark's log: ${out}"
