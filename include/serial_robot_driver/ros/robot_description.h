// The URDF of the configured robot (serial_robot_driver/description/robot_description.h) with the
// servo joints the ROS layer derives from the parameters: one revolute joint per body joint and per
// bus-servo joint, each limited to what its servo reaches. The robot_description executable prints
// it; launch/description.launch loads it.
#pragma once

#include <string>
#include <vector>

#include "serial_robot_driver/description/robot_description.h"
#include "serial_robot_driver/ros/driver_params.h"

namespace serial_robot_driver::ros_layer {

using description::ImuMount;
using description::linkName;
using description::YamlParamSource;

/// The servo joints of the enabled body and servo bus, with the range each servo reaches through
/// the joint's zero and direction. `params` must have passed validate().
std::vector<description::ServoJoint> servoJoints(const DriverParams& params);

/// The URDF document with servoJoints(params). `params` must have passed validate(). Throws
/// ParameterError when two joints or links would share a name.
std::string makeRobotDescription(const DriverParams& params, const ImuMount& imu,
                                 const std::string& robot_name);

}  // namespace serial_robot_driver::ros_layer
