#!/usr/bin/env bash
# A long run of the ROS 2 (DDS) interface fuzzer: dds_driver_tests' seeded random test
# (DdsDriver.SeededRandomHostileInputLeavesTheDriverWorking): random picks of hostile samples
# (test/dds_front/hostile_dds_inputs.cpp) and random bytes on every DDS input of dds_driver against
# robot_sim, then a valid cmd_vel must still drive the base. Needs a workspace built with Cyclone
# DDS (scripts/build.sh; make dds_driver_tests). The sibling of scripts/fuzz_ros_interface.sh.
#   bash scripts/fuzz_dds_interface.sh [COUNT [SEED]]
# COUNT: inputs per run (default 5000, about 2 minutes; at most 200000); SEED: the first run's seed
# (default: from the clock). RUNS=N repeats with SEED, SEED+1, ... A failure prints the seed.
set -euo pipefail
cd "$(dirname "$0")/.."
count="${1:-5000}"
seed="${2:-$(date +%s)}"
runs="${RUNS:-1}"
if ((count > 200000)); then count=200000; fi
tests=".ws/devel/lib/serial_robot_driver/dds_driver_tests"
if [[ ! -x "$tests" ]]; then
  echo "fuzz_dds_interface: $tests not built (needs Cyclone DDS; make dds_driver_tests)" >&2
  exit 2
fi
for ((run = 0; run < runs; run++)); do
  this_seed=$((seed + run))
  echo "fuzz_dds_interface: run $((run + 1))/$runs, seed $this_seed, $count inputs"
  log="$(mktemp /tmp/fuzz_dds_interface.XXXXXX.log)"
  if ! SRD_FUZZ_SEED="$this_seed" SRD_DDS_FUZZ_COUNT="$count" timeout 1800 "$tests" \
      --gtest_filter='DdsDriver.SeededRandom*' >"$log" 2>&1; then
    grep -E "Failure|seed|terminate|what\(\)" "$log" || true
    echo "fuzz_dds_interface: FAILED with seed $this_seed (log: $log); repeat with:"
    echo "  RUNS=1 bash scripts/fuzz_dds_interface.sh $count $this_seed"
    exit 1
  fi
  rm -f "$log"
done
echo "fuzz_dds_interface: $runs run(s) of $count inputs passed"
