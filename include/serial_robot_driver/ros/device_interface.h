// A device's ROS side: the core device contract (device/device.h) with the device's topics and
// services around it, built by its RosDeviceModule. DriverNode turns its status() into a
// DiagnosticStatus under the name it was registered under (device/device_module.h).
#pragma once

#include "serial_robot_driver/core/device.h"

namespace serial_robot_driver::ros_layer {

using trajectory::TrajectoryJoints;

class DeviceInterface : public core::Device {};

}  // namespace serial_robot_driver::ros_layer
