// The driver's parameters (params/driver_params.h, ROS-free) read from the parameter server.
#pragma once

#include <string>
#include <vector>

#include "serial_robot_driver/params/driver_params.h"

namespace ros {
class NodeHandle;
}

namespace serial_robot_driver::ros_layer {

// The ROS layer uses the core's parameter types under their own names.
using params::DevicePortParams;
using params::DriverParams;
using params::loadParams;
using params::ParamAssignment;
using params::ParameterError;
using params::parameterTable;
using params::ParamSource;
using params::ParamSpec;
using params::ParamValue;
using params::resolveFrame;
using params::toText;
using params::TrajectoryParams;
using params::tuneParams;
using params::TuningResult;

/// Reads every parameter from the private namespace of `private_nh` (missing keys keep their
/// defaults; a key of the wrong type is a ParameterError), then `tf_prefix` searched upward from
/// the node's namespace, and puts the frame parameters under it. `unknown_keys` receives the keys
/// under ~ that the driver does not know (typos), for a warning.
DriverParams loadParams(const ros::NodeHandle& private_nh, std::vector<std::string>* unknown_keys);

}  // namespace serial_robot_driver::ros_layer
