// The URDF of the configured robot (serial_robot_driver/description/robot_description.h), as the
// robot_description executable and its tests reach it. The robot_description executable prints
// it; launch/description.launch loads it.
#pragma once

#include "serial_robot_driver/description/robot_description.h"
#include "serial_robot_driver/ros/driver_params.h"

namespace serial_robot_driver::ros_layer {

using description::linkName;
using description::makeRobotDescription;
using description::Mount;
using description::mountPoints;
using description::Mounts;
using description::servoJoints;
using description::YamlParamSource;

}  // namespace serial_robot_driver::ros_layer
