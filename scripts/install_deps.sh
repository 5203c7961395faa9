#!/usr/bin/env bash
# Installs what a fresh Debian 12 machine lacks to build, run and test serial_robot_driver
# (ROS 1 from Debian's packages). Idempotent and quiet: apt-get runs only when something is missing.
# The python3-*-msgs/-srvs packages are what `rostopic echo` and `rosservice call` need to load the
# types the node publishes and serves ("Cannot load message class" without them).
set -euo pipefail

PACKAGES=(
  build-essential cmake pkg-config
  ros-base-dev catkin python3-catkin-pkg
  libstd-msgs-dev libsensor-msgs-dev libgeometry-msgs-dev libstd-srvs-dev
  libdiagnostic-msgs-dev libdiagnostic-updater-dev ros-message-generation ros-message-runtime
  libnav-msgs-dev libtf2-ros-dev libtf2-msgs-dev tf2-tools
  libnodelet-dev libnodeletlib-dev libnodeletlib-tools pluginlib-dev
  librosbag-dev librosbag-storage-dev libdiagnostic-aggregator-dev
  librostest-dev python3-rostest python3-rosbag rosbash
  python3-std-msgs python3-geometry-msgs python3-sensor-msgs python3-nav-msgs
  python3-diagnostic-msgs python3-tf2-msgs python3-std-srvs python3-trajectory-msgs
  python3-actionlib-msgs python3-rostopic python3-rosservice libdiagnostic-aggregator-tools
  libeigen3-dev libboost-dev googletest libgtest-dev libbenchmark-dev
  clang libclang-rt-14-dev catkin-lint catkin-tools ccache
  libactionlib-dev libactionlib-msgs-dev libtrajectory-msgs-dev
  python3-actionlib python3-actionlib-msgs python3-trajectory-msgs
)
# The robot description (robot_description, description.launch, view.launch) and its tests.
PACKAGES+=(libyaml-cpp-dev liburdf-dev liburdfdom-tools ros-robot-state-publisher
           joint-state-publisher topic-tools rviz)
# Runtime tuning: the dynamic_reconfigure server, its .cfg generator, its Python client and dynparam.
PACKAGES+=(libdynamic-reconfigure-config-init-mutex-dev python3-dynamic-reconfigure)
# ROS 2 through DDS (srd_dds, optional in CMake): Cyclone DDS, its IDL compiler idlc, libcrypto for
# the REP-2011 type hashes; Fast DDS and its generator for tests against an independent DDS.
PACKAGES+=(cyclonedds-dev cyclonedds-tools libssl-dev libfastrtps-dev fastddsgen)
# --dev: what scripts/screenshot_view.sh needs to remake docs/images/ (a virtual display, a grab).
[ "${1:-}" != "--dev" ] || PACKAGES+=(xvfb imagemagick)

missing=()
for package in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed" || missing+=("$package")
done
if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi
echo "installing: ${missing[*]}"
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
