// The whole life of a driver_node process (signals, parameters, DriverNode, spinning, the last
// zero-speed frame), shared by the node's main and by benchmark builds of the same node.
#pragma once

#include <ros/ros.h>

#include <functional>

#include "serial_robot_driver/core/serial_link.h"
#include "serial_robot_driver/ros/driver_params.h"

namespace serial_robot_driver::ros_layer {

/// Builds the ports' stream factory from the node's private namespace before the driver
/// parameters are loaded (it may read, and must then delete, parameters of its own). An empty
/// factory means termios serial ports; throwing ParameterError stops the node with that message.
using StreamFactoryMaker =
    std::function<core::SerialLink::StreamFactory(ros::NodeHandle& private_nh)>;

/// Loads the driver's parameters from `private_nh`, warns about unknown keys (typos) and
/// validates them; throws ParameterError. Shared by driver_node and the nodelet.
DriverParams loadCheckedParams(const ros::NodeHandle& private_nh);

/// Runs the node until SIGINT/SIGTERM or a roscpp shutdown; returns the process exit code.
int runDriverNode(int argc, char** argv, const StreamFactoryMaker& make_stream_factory = {});

}  // namespace serial_robot_driver::ros_layer
