// A device's ROS front end: the device's topics, services and their messages around the core
// device it attaches to (core/device.h; built and owned by core::DriverCore), built by its
// RosDeviceModule. It converts messages to the device's inputs and the device's outputs to
// messages, nothing more: the checks, the counting and the log lines are the device's.
#pragma once

namespace serial_robot_driver::ros_layer {

class DeviceFrontEnd {
 public:
  virtual ~DeviceFrontEnd() = default;
  /// After the core started the ports and the devices: starts what serves on threads of its own.
  virtual void start() {}
  /// After the core shut the devices down: stops taking requests and joins its threads.
  /// Idempotent.
  virtual void shutdown() {}
};

}  // namespace serial_robot_driver::ros_layer
