// A device's ROS side: the core device contract (device/device.h) with the device's topics and
// services around it. DriverNode adds its diagnostic status under the name it was registered under
// (device/device_module.h).
#pragma once

#include <diagnostic_updater/diagnostic_updater.h>

#include "serial_robot_driver/device/device.h"

namespace serial_robot_driver::ros_layer {

using trajectory::TrajectoryJoints;

class DeviceInterface : public device::Device {
 public:
  /// Writes status() into `status`: the one place a device's status becomes a DiagnosticStatus.
  /// A device with a check of diagnostic_updater's own (the body's telemetry rate) adds it here.
  virtual void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status);
};

}  // namespace serial_robot_driver::ros_layer
