// The base's parameter section (~base/...): rows in src/devices/base/base_module.cpp.
#pragma once

#include <string>

#include "serial_robot_driver/devices/base/base_controller.h"
#include "serial_robot_driver/params/device_sections.h"
#include "serial_robot_driver/params/port_params.h"

namespace serial_robot_driver::params {
struct DriverParams;
}  // namespace serial_robot_driver::params

namespace serial_robot_driver::devices::base {

/// The base's parameters. Those that configure the controller are bound straight into
/// `controller` (their defaults are its own); the rest are the ROS layer's and the checks'.
struct BaseParams : params::DevicePortParams {
  /// The controller's configuration as the parameters set it. Not parameters of this section:
  /// loop_rate and baud, which makeBaseConfig fills in from the node-wide values, and
  /// imu_yaw_variance, which the heading's source gives (core::HeadingSource::yawVariance).
  BaseConfig controller;
  int battery_warn_percent = 20;   ///< below: diagnostics WARN
  int battery_error_percent = 10;  ///< below: diagnostics ERROR
  std::string odom_frame = "odom";
  std::string base_frame = "base_link";
  bool publish_tf = true;
  std::string left_wheel_joint = "left_wheel_joint";  ///< wheel_states and robot description names
  std::string right_wheel_joint = "right_wheel_joint";
};

/// The key of the base's section (DeviceModule::sections): params.section(kBaseSection).
extern const params::SectionKey<BaseParams> kBaseSection;

/// The controller's configuration to start with: the base's own parameters (bound into
/// `controller` already, base_module.cpp) plus the node-wide loop rate and the port's baud.
BaseConfig makeBaseConfig(const params::DriverParams& params);

/// Below this loop rate the base's 1 s heartbeat is at risk (the base's checks say so).
constexpr double kMinBaseLoopRate = 5.0;

}  // namespace serial_robot_driver::devices::base
