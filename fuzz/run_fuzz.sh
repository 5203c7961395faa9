#!/usr/bin/env bash
# Builds the fuzz targets with clang and runs each for a share of the given time.
#   fuzz/run_fuzz.sh [total_seconds]     (default 30: a CI smoke run, 4 s per target)
#   fuzz/run_fuzz.sh --build-only        (builds the targets, runs none)
# Environment: FUZZ_BUILD (build directory, default /tmp/fuzzbuild).
# Exits non-zero when a target crashes, leaks, times out or reports undefined behaviour; the input
# that did it is saved as $FUZZ_BUILD/artifacts/<target>-crash-*.
# Needs clang and libFuzzer (Debian/Ubuntu: clang libclang-rt-14-dev), Eigen3 and Boost headers.
set -euo pipefail

build_only=false
if [ "${1:-}" = --build-only ]; then build_only=true; shift; fi
total="${1:-30}"
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
build="${FUZZ_BUILD:-/tmp/fuzzbuild}"
# fuzz_decoders covers every registered family, those without a target of their own too.
targets=(fuzz_framer fuzz_decoders fuzz_base fuzz_telemetry fuzz_servo_response fuzz_servo_request
         fuzz_sync_write)
per_target=$(( total / ${#targets[@]} ))
(( per_target >= 1 )) || per_target=1

CC="${CC:-clang}" CXX="${CXX:-clang++}" cmake -S "$here" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
cmake --build "$build" -j2 -- --no-print-directory >/dev/null
[ "$build_only" = false ] || exit 0
bash "$here/make_corpus.sh" "$build/seeds" >/dev/null

# run_target <target>: fuzzes it for per_target seconds and prints a summary; a finding leaves
# $build/<target>.failed.
run_target() {
  local target="$1"
  # New inputs go to a scratch corpus in the build tree; the generated seeds stay read-only.
  local work="$build/corpus/$target" log="$build/$target.log" seeds="$build/seeds/$target"
  mkdir -p "$work" "$build/artifacts"
  rm -f "$build/$target.failed"
  echo "== $target: ${per_target} s"
  [ -d "$seeds" ] || seeds="$build/seeds/fuzz_decoders"  # per-decoder targets share those seeds
  if "$build/$target" "$work" "$seeds" \
      -max_total_time="$per_target" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
      -artifact_prefix="$build/artifacts/$target-" >"$log" 2>&1; then
    execs="$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)"
    cover="$(grep -o 'cov: [0-9]*' "$log" | tail -1 || true)"
    echo "   ok: ${execs:-?} execs, ${cover:-cov: ?}"
  else
    touch "$build/$target.failed"
    echo "   FAILED (log: $log)"
    grep -E 'ERROR|SUMMARY|runtime error|Test unit written' "$log" | head -20 || true
  fi
}

# Targets run side by side, one per core (FUZZ_JOBS), each for the same per_target seconds as one
# at a time; the summaries are printed in the list's order.
jobs_max="${FUZZ_JOBS:-$(nproc)}"
for target in "${targets[@]}"; do
  while [ "$(jobs -rp | wc -l)" -ge "$jobs_max" ]; do wait -n || true; done
  run_target "$target" > "$build/$target.summary" &
done
wait
status=0
for target in "${targets[@]}"; do
  cat "$build/$target.summary"
  [ ! -e "$build/$target.failed" ] || status=1
done
exit "$status"
