#!/usr/bin/env bash
# Builds the fuzz targets with clang and runs each for a share of the given time.
#   fuzz/run_fuzz.sh [total_seconds]     (default 30: a CI smoke run, 4 s per target)
# Environment: FUZZ_BUILD (build directory, default /tmp/fuzzbuild).
# Exits non-zero when a target crashes, leaks, times out or reports undefined behaviour; the input
# that did it is saved as $FUZZ_BUILD/artifacts/<target>-crash-*.
# Needs clang and libFuzzer (Debian/Ubuntu: clang libclang-rt-14-dev), Eigen3 and Boost headers.
set -euo pipefail

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
bash "$here/make_corpus.sh" "$build/seeds" >/dev/null

status=0
for target in "${targets[@]}"; do
  # New inputs go to a scratch corpus in the build tree; the generated seeds stay read-only.
  work="$build/corpus/$target"
  mkdir -p "$work" "$build/artifacts"
  log="$build/$target.log"
  echo "== $target: ${per_target} s"
  seeds="$build/seeds/$target"
  [ -d "$seeds" ] || seeds="$build/seeds/fuzz_decoders"  # per-decoder targets share those seeds
  if "$build/$target" "$work" "$seeds" \
      -max_total_time="$per_target" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
      -artifact_prefix="$build/artifacts/$target-" >"$log" 2>&1; then
    execs="$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)"
    cover="$(grep -o 'cov: [0-9]*' "$log" | tail -1 || true)"
    echo "   ok: ${execs:-?} execs, ${cover:-cov: ?}"
  else
    status=1
    echo "   FAILED (log: $log)"
    grep -E 'ERROR|SUMMARY|runtime error|Test unit written' "$log" | head -20 || true
  fi
done
exit "$status"
