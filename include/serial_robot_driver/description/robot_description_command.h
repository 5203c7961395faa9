// robot_description's command line (src/nodes/robot_description_main.cpp only calls it):
//   robot_description CONFIG.yaml [--<mount>-xyz "X Y Z"] [--<mount>-rpy "R P Y"] [--name NAME]
// prints the URDF of the robot a driver parameter file configures, for
// `<param name="robot_description" command="$(find serial_robot_driver)/... CONFIG"/>`. The file
// is read with the driver's own defaults and checks (loadParams, validate()). ROS-free, so that the
// arguments, the texts and the exit statuses are unit-tested without running the executable.
#pragma once

#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "serial_robot_driver/description/robot_description.h"

namespace serial_robot_driver::description {

/// What to describe: the parameter file, the robot's name and where its parts sit.
struct DescriptionRequest {
  std::string config;
  std::string name = "serial_robot";
  Mounts mounts;
};

/// The arguments read: a request, or help asked for, or what to print on stderr (exit status 2).
struct ParsedDescriptionArguments {
  std::optional<DescriptionRequest> request;  ///< unset when help or on a bad argument
  bool help = false;                          ///< -h or --help: print descriptionUsage()
  std::string error;                          ///< the message for a bad argument ("" otherwise)
};

/// The usage text, with the mounts the devices' parts take (mountPoints()).
std::string descriptionUsage();

/// Reads robot_description's arguments (without the program's name), in order: the first one
/// that is wrong is the error.
ParsedDescriptionArguments parseDescriptionArguments(const std::vector<std::string>& args);

/// The whole command: the URDF on `out` and 0; the usage on `out` and 0 for help; a message on
/// `err` and 2 for bad arguments, 1 for a file that cannot be read or fails the driver's checks.
int runRobotDescription(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);

}  // namespace serial_robot_driver::description
