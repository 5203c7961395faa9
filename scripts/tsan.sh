#!/usr/bin/env bash
# ThreadSanitizer run: builds the package with -fsanitize=thread in a workspace of its own
# (.ws_tsan/, kept between runs) and runs the core unit tests and the e-stop rostests under it.
# Not part of CI (a second full build and a slow run); run it after touching threads or locks:
#   bash scripts/tsan.sh            # core_tests, estop_bus.test, safe_motion.test
#   bash scripts/tsan.sh --unit     # core_tests only
# Reports go to .ws_tsan/reports/tsan.<pid>; the script prints those that name project code
# (src/, include/, test/) and exits non-zero when there is one.
set -uo pipefail
repo="$(cd "$(dirname "$0")/.." && pwd)"
ws="$repo/.ws_tsan"
export PATH="/usr/bin:$PATH"
bash "$repo/scripts/install_deps.sh" || exit 1

mkdir -p "$ws/src" "$ws/devel/lib/python3/dist-packages" "$ws/reports"
ln -sfn "$repo" "$ws/src/serial_robot_driver"
flags="-fsanitize=thread -g -O1"
(cd "$ws" && catkin_make -DPYTHON_EXECUTABLE=/usr/bin/python3 -DCMAKE_BUILD_TYPE=RelWithDebInfo \
   -DCATKIN_ENABLE_TESTING=ON -DCMAKE_CXX_FLAGS="$flags" -DCMAKE_EXE_LINKER_FLAGS=-fsanitize=thread \
   -DCMAKE_SHARED_LINKER_FLAGS=-fsanitize=thread -j2 \
   core_tests driver_node robot_sim test_estop_bus test_safe_motion) > "$ws.build.log" 2>&1 \
  || { tail -n 40 "$ws.build.log"; echo "tsan build failed"; exit 1; }
set +u
source "$ws/devel/setup.bash"
set -u

rm -f "$ws"/reports/tsan.*
# second_deadlock_stack: lock-order reports name both stacks; halt_on_error=0: collect them all.
export TSAN_OPTIONS="log_path=$ws/reports/tsan second_deadlock_stack=1 halt_on_error=0"
status=0
"$ws/devel/lib/serial_robot_driver/core_tests" --gtest_brief=1 > "$ws/core_tests.log" 2>&1 || status=1
tail -n 3 "$ws/core_tests.log"
if [ "${1:-}" != "--unit" ]; then
  for test in estop_bus.test safe_motion.test; do
    rostest serial_robot_driver "$test" > "$ws/$test.log" 2>&1 || status=1
    grep -E "^\[ *(PASSED|FAILED)|tests, .* failures" "$ws/$test.log" | tail -n 3
  done
fi

project_reports=0
for report in "$ws"/reports/tsan.*; do
  [ -e "$report" ] || continue
  if grep -qE "serial_robot_driver/(src|include|test)/" "$report"; then
    project_reports=$((project_reports + 1))
    echo "== $report"
    grep -E "^WARNING|#[0-9]+ .*serial_robot_driver/(src|include|test)/" "$report" | head -n 20
  fi
done
echo "ThreadSanitizer: $project_reports report file(s) naming project code"
[ "$project_reports" -eq 0 ] && [ "$status" -eq 0 ]
