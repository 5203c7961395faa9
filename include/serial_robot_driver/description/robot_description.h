// The URDF of the configured robot, built from the same parameter file driver_node loads (what
// xacro would do, without xacro), composed of what each device draws (its DescriptionPart, in
// src/devices/<name>/description/): the chassis with its root link, fixed parts placed on it, and
// one revolute joint per servo joint in a row across it, each limited to what its servo reaches.
// ROS-free: the YAML file is read with yaml-cpp, the URDF is text (urdf_writer.h).
#pragma once

#include <array>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "serial_robot_driver/description/urdf_writer.h"
#include "serial_robot_driver/params/driver_params.h"
#include "serial_robot_driver/params/yaml_param_source.h"

namespace serial_robot_driver::description {

using params::DriverParams;
using params::ParameterError;
using params::ParamSource;
using params::ParamValue;
using params::YamlParamSource;

/// Where a part sits on the chassis (a --<name>-xyz / --<name>-rpy argument).
struct Mount {
  std::array<double, 3> xyz{0, 0, 0};  ///< m in the root link's frame
  std::array<double, 3> rpy{0, 0, 0};  ///< rad, URDF order (roll, pitch, yaw)
};
/// The mounts given, by name (unnamed ones: all zero).
using Mounts = std::map<std::string, Mount>;
/// The mount a part is placed by, all zero when not given.
Mount mountOf(const Mounts& mounts, const std::string& name);

/// A revolute servo joint with its reachable range.
struct ServoJoint {
  std::string name;
  std::string key;  ///< the parameter that names it, for errors
  double lower, upper;
  double velocity;  ///< rad/s limit
};

/// The chassis the other parts are drawn on: its root link and the room on top for servo arms.
struct Chassis {
  std::string root_link;
  double length = 0.0, width = 0.0;  ///< m
  double top = 0.0;                  ///< m, the height of the servos' axes
  double arm_length = 0.0;           ///< m, a servo's arm
};

/// A mount a part takes from the command line: --<name>-xyz and --<name>-rpy place `what`.
struct MountPoint {
  std::string name;
  std::string what;
};

/// What one device adds to the robot description; each function may be empty.
struct DescriptionPart {
  std::vector<MountPoint> mounts{};
  /// Draws the root link and what hangs off it, and answers the chassis. One device draws it.
  std::function<Chassis(const DriverParams& params, UrdfWriter& urdf)> chassis{};
  /// Draws fixed parts (sensors) on the chassis, placed by `mounts`.
  std::function<void(const DriverParams& params, const Chassis& chassis, const Mounts& mounts,
                     UrdfWriter& urdf)>
      fixed{};
  /// The device's servo joints (drawn by makeRobotDescription, every device's in one row).
  std::function<std::vector<ServoJoint>(const DriverParams& params)> servo_joints{};
};

/// Every device's part, in SRD_DEVICES order (generated from cmake/devices.cmake); devices that
/// draw nothing have none.
const std::vector<const DescriptionPart*>& registeredDescriptionParts();

/// The mounts every part takes, in device order.
std::vector<MountPoint> mountPoints();

/// A frame parameter as a URDF link name: robot_state_publisher adds the tf_prefix itself, so a
/// leading '/' (which keeps the driver from prefixing) is dropped.
std::string linkName(const std::string& frame);

/// The servo joints of every enabled device, in device order. `params` must have passed
/// validate().
std::vector<ServoJoint> servoJoints(const DriverParams& params);

/// The URDF document: every part's chassis, then fixed parts, then the servo joints in a row
/// across the chassis. `params` must have passed validate(). Throws ParameterError when two joints
/// or links would share a name, std::logic_error when no device draws the chassis.
std::string makeRobotDescription(const DriverParams& params, const Mounts& mounts,
                                 const std::string& robot_name);

}  // namespace serial_robot_driver::description
