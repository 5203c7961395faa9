// A device's ROS side, registered like its core module (core/device_module.h) and found by the
// same name: DriverNode attaches the front end of every enabled device to the device the core
// built. Defined in the device's folder (src/devices/<name>/ros/), which is the one place that
// knows the core device's class.
#pragma once

#include <ros/node_handle.h>

#include <memory>
#include <vector>

#include "serial_robot_driver/core/device.h"
#include "serial_robot_driver/core/device_module.h"
#include "serial_robot_driver/ros/device_front_end.h"
#include "serial_robot_driver/ros/driver_params.h"
#include "serial_robot_driver/ros/runtime_tuning.h"

namespace serial_robot_driver::ros_layer {

/// Declared with named fields (designated initialisers); a field left out is null.
struct RosDeviceModule {
  /// The core module's name (DeviceModule::name).
  const char* name = nullptr;
  /// Builds the device's front end on `device` (made by its core module's make_device), before
  /// the core starts: it registers its outputs with the device. `device` outlives it.
  std::unique_ptr<DeviceFrontEnd> (*attach)(ros::NodeHandle& nh, const DriverParams& params,
                                            core::Device& device) = nullptr;
  /// Starts the device's runtime tuning servers (addGroupServer, ros/tuning_group_server.h) under
  /// `private_nh` into `servers`; RuntimeTuning calls it while the device is enabled. Null: the
  /// device has nothing to tune.
  void (*add_tuning)(RuntimeTuning& tuning, const ros::NodeHandle& private_nh,
                     RuntimeTuning::Servers& servers) = nullptr;
};

/// The registered devices' ROS sides, in the order of the devices (cmake/devices.cmake).
const std::vector<const RosDeviceModule*>& registeredInterfaces();
/// The ROS side of the device called `name`, or null.
inline const RosDeviceModule* findInterface(const std::string& name) {
  return core::findByName(registeredInterfaces(), name);
}

}  // namespace serial_robot_driver::ros_layer
