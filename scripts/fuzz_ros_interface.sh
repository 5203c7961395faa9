#!/usr/bin/env bash
# A long run of the ROS interface fuzzer (test/rostest/ros_interface_fuzz.test): seeded extreme
# inputs on every topic and service of driver_node against the simulated robot, part of them under
# the e-stop. Needs a built workspace (scripts/build.sh).
#   bash scripts/fuzz_ros_interface.sh [COUNT [SEED]]
# COUNT: inputs per run (default 20000, about 4 minutes); SEED: the first run's seed (default: from
# the clock). RUNS=N repeats with SEED, SEED+1, ... A failure prints the seed that repeats it.
set -euo pipefail
cd "$(dirname "$0")/.."
count="${1:-20000}"
seed="${2:-$(date +%s)}"
runs="${RUNS:-1}"
set +u  # ROS's setup scripts read unset variables
# shellcheck disable=SC1091
source .ws/devel/setup.bash
set -u
for ((run = 0; run < runs; run++)); do
  this_seed=$((seed + run))
  echo "fuzz_ros_interface: run $((run + 1))/$runs, seed $this_seed, $count inputs"
  log="$(mktemp /tmp/fuzz_ros_interface.XXXXXX.log)"
  if ! SRD_FUZZ_SEED="$this_seed" SRD_FUZZ_COUNT="$count" \
      rostest --text serial_robot_driver ros_interface_fuzz.test >"$log" 2>&1; then
    grep -E "ros_interface_fuzz:|Failure|died|terminate|what\(\)" "$log" || true
    echo "fuzz_ros_interface: FAILED with seed $this_seed (log: $log); repeat with:"
    echo "  SRD_FUZZ_SEED=$this_seed SRD_FUZZ_COUNT=$count rostest --text serial_robot_driver ros_interface_fuzz.test"
    exit 1
  fi
  grep -E "ros_interface_fuzz: [0-9]+ inputs" "$log" || true
  rm -f "$log"
done
echo "fuzz_ros_interface: $runs run(s) of $count inputs passed"
