// The base's parameter section (~base/...): rows in src/devices/base/base_module.cpp.
#pragma once

#include <string>

#include "serial_robot_driver/devices/base/base_controller.h"
#include "serial_robot_driver/params/port_params.h"

namespace serial_robot_driver::params {

/// The defaults of the base controller's configuration: the parameters that configure it start
/// from its values, so each default is written once (in the core config), never copied.
inline const device::BaseConfig kBaseDefaults{};

struct BaseParams : DevicePortParams {
  double wheel_diameter = kBaseDefaults.geometry.wheel_diameter;
  int encoder_resolution = static_cast<int>(kBaseDefaults.geometry.encoder_resolution);
  double pid_rate = kBaseDefaults.geometry.pid_rate;
  double wheel_separation = kBaseDefaults.geometry.wheel_separation;
  double max_wheel_speed = kBaseDefaults.max_wheel_speed;
  double max_wheel_accel = kBaseDefaults.max_wheel_accel;
  double cmd_vel_timeout = kBaseDefaults.cmd_vel_timeout;
  bool speed_dithering = kBaseDefaults.speed_dithering;
  double battery_poll_rate = kBaseDefaults.battery_poll_rate;
  int battery_warn_percent = 20;   ///< below: diagnostics WARN
  int battery_error_percent = 10;  ///< below: diagnostics ERROR
  std::string odom_frame = "odom";
  std::string base_frame = "base_link";
  bool publish_tf = true;
  /// 1 or -1: sign between forward motion and the wire's ticks
  int left_wheel_direction = kBaseDefaults.left_wheel_direction;
  int right_wheel_direction = kBaseDefaults.right_wheel_direction;
  std::string left_wheel_joint = "left_wheel_joint";  ///< wheel_states and robot description names
  std::string right_wheel_joint = "right_wheel_joint";
  /// odom's heading from the body's IMU while its telemetry is fresh (device::BaseConfig).
  bool use_imu_heading = kBaseDefaults.use_imu_heading;
};

/// Below this loop rate the base's 1 s heartbeat is at risk (the base's checks say so).
constexpr double kMinBaseLoopRate = 5.0;

}  // namespace serial_robot_driver::params
