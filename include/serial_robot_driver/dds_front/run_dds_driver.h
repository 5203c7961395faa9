// The whole life of a dds_driver process: the driver serving a ROS 2 graph only, with no ROS 1
// master (INTERFACE.md, "ROS 2 (through DDS)"):
//   dds_driver --config FILE [--name NAME] [--namespace NS]
// FILE holds the private parameters as top-level keys (the `rosparam load` form of
// config/robot.yaml), read through the node's own table and checks (params/yaml_param_source.h).
// SIGINT and SIGTERM stop it as they stop driver_node: the devices' last words (the base's
// zero-speed frame, the bus servos' stops) are written before the ports close.
#pragma once

#include <string>

namespace serial_robot_driver::dds_front {

struct DdsDriverOptions {
  std::string config;                ///< the parameter file
  std::string name = "driver_node";  ///< the ROS 2 node name
  std::string node_namespace = "/";  ///< its namespace
};

/// The usage text.
std::string ddsDriverUsage();

/// Reads the command line; throws std::invalid_argument (with what is wrong) for an unknown
/// argument, a missing value or no --config. `help` is set for -h / --help.
DdsDriverOptions parseDdsDriverArguments(int argc, const char* const* argv, bool* help);

/// Runs the driver until SIGINT/SIGTERM; returns the exit status: 0 after an orderly stop, 2 for a
/// bad command line or parameter (one message naming it), 1 when the DDS graph cannot be joined.
int runDdsDriver(int argc, const char* const* argv);

}  // namespace serial_robot_driver::dds_front
