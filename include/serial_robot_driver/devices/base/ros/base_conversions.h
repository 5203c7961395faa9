// The base's readings as ROS messages: battery, odom and the wheels' joint states. The values are
// the core's (devices/base/base_readings.h, device::OdometrySample); these only copy them. No node,
// no I/O, so they are unit-tested without a roscore.
#pragma once

#include <nav_msgs/Odometry.h>
#include <ros/time.h>
#include <sensor_msgs/BatteryState.h>
#include <sensor_msgs/JointState.h>

#include <string>
#include <string_view>

#include "serial_robot_driver/devices/base/base_controller.h"
#include "serial_robot_driver/devices/base/base_readings.h"

namespace serial_robot_driver::devices::base::ros {

/// The charge as `percentage`; what the base does not report is NaN or UNKNOWN (the message's
/// convention), and the battery is present.
sensor_msgs::BatteryState toBatteryState(const BatteryReading& battery, const ::ros::Time& stamp);

/// The odom frames: `odom` the header's, `base` the child's (views: the names are copied into the
/// message, not kept).
struct OdomFrames {
  std::string_view odom;
  std::string_view base;
};
/// Pose, twist and their covariances (row-major 6x6: x, y, z, roll, pitch, yaw).
nav_msgs::Odometry toOdometry(const OdometrySample& sample, const OdomFrames& frames,
                              const ::ros::Time& stamp);
/// The same into `msg` (every field), reusing its frame names' buffers: the loop's message of the
/// last tick, filled again without allocating.
void fillOdometry(const OdometrySample& sample, const OdomFrames& frames, const ::ros::Time& stamp,
                  nav_msgs::Odometry* msg);

/// The wheels' angles (rad) and rates (rad/s) under joints `left` and `right`, in `frame`.
sensor_msgs::JointState toWheelStates(const OdometrySample& sample, const std::string& frame,
                                      const std::string& left, const std::string& right,
                                      const ::ros::Time& stamp);
/// The same into `msg` (every field), reusing its strings and vectors: the loop's message of the
/// last tick, filled again without allocating.
void fillWheelStates(const OdometrySample& sample, const std::string& frame,
                     const std::string& left, const std::string& right, const ::ros::Time& stamp,
                     sensor_msgs::JointState* msg);

}  // namespace serial_robot_driver::devices::base::ros
