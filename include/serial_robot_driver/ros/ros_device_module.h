// A device's ROS side, registered like its core module (device/device_module.h) and found by
// the same name: DriverNode builds the interface of every enabled device from it. Defined in the
// device's folder (src/devices/<name>/ros/).
#pragma once

#include <ros/node_handle.h>

#include <memory>
#include <vector>

#include "serial_robot_driver/core/serial_link.h"
#include "serial_robot_driver/ros/device_interface.h"
#include "serial_robot_driver/ros/runtime_tuning.h"

namespace serial_robot_driver::ros_layer {

/// Declared with named fields (designated initialisers); a field left out is null.
struct RosDeviceModule {
  /// The core module's name (DeviceModule::name).
  const char* name = nullptr;
  /// Builds the device's interface on its port (before the ports start).
  std::unique_ptr<DeviceInterface> (*make)(ros::NodeHandle& nh, const DriverParams& params,
                                           core::SerialLink& link) = nullptr;
  /// Starts the device's runtime tuning servers (addGroupServer, ros/tuning_group_server.h) under
  /// `private_nh` into `servers`; RuntimeTuning calls it while the device is enabled. Null: the
  /// device has nothing to tune.
  void (*add_tuning)(RuntimeTuning& tuning, const ros::NodeHandle& private_nh,
                     RuntimeTuning::Servers& servers) = nullptr;
};

/// The registered devices' ROS sides, in the order of the devices (cmake/devices.cmake).
const std::vector<const RosDeviceModule*>& registeredInterfaces();
/// The ROS side of the device called `name`, or null.
const RosDeviceModule* findInterface(const std::string& name);

/// RosDeviceModule::make for an interface constructed from (nh, params, link).
template <typename Interface>
std::unique_ptr<DeviceInterface> makeInterface(ros::NodeHandle& nh, const DriverParams& params,
                                               core::SerialLink& link) {
  return std::make_unique<Interface>(nh, params, link);
}

}  // namespace serial_robot_driver::ros_layer
