// ROS front end of the AP1 base (devices::base::BaseDevice): cmd_vel in; wheel_command, odom
// (+ tf), wheel_states and battery out; base/reset, base/clear_encoders and base/reset_odometry
// services. odom and tf are published from the device's loop thread, once per tick. odom is the
// motion the base was commanded and accepted, not a measurement: the AP1 reports no encoder counts.
#pragma once

#include <geometry_msgs/Twist.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>
#include <std_srvs/Trigger.h>
#include <tf2_msgs/TFMessage.h>

#include <memory>

#include "serial_robot_driver/devices/base/base_device.h"
#include "serial_robot_driver/ros/conversions.h"
#include "serial_robot_driver/ros/device_front_end.h"
#include "serial_robot_driver/ros/driver_params.h"
#include "serial_robot_driver/ros/publish_wanted.h"

namespace serial_robot_driver::devices::base::ros {

class BaseRos : public ros_layer::DeviceFrontEnd {
 public:
  /// Advertises the topics and services and adds its outputs to `device` (before it starts).
  /// `device` must outlive this object.
  BaseRos(::ros::NodeHandle& nh, const ros_layer::DriverParams& params, BaseDevice& device);

 private:
  BaseOutputs outputs();
  void publishWheelCommand(const WheelFrameSent& sent);
  void publishOdometry(const OdometrySample& sample);
  /// odom's pose as odom -> base_link, into tf_.
  void buildTf(const nav_msgs::Odometry& odom, const OdometrySample& sample);
  static ros_layer::CountedPublisher advertiseTf();
  /// The wheels' joint states, into wheel_states_.
  void buildWheelStates(const OdometrySample& sample, const ::ros::Time& stamp);

  BaseDevice& device_;
  ros_layer::ArrivalStamps arrival_stamps_;
  ros_layer::CountedPublisher tf_pub_;  // /tf; advertised by the loop thread when first needed
  ros_layer::CountedPublisher odom_pub_;
  ros_layer::CountedPublisher wheel_states_pub_;
  ros_layer::CountedPublisher wheel_command_pub_;
  ros_layer::CountedPublisher battery_pub_;
  // The loop thread's messages of the last tick, filled again (published by value: roscpp
  // serializes them before publish() returns).
  nav_msgs::Odometry odom_;
  sensor_msgs::JointState wheel_states_;
  tf2_msgs::TFMessage tf_;
  ::ros::Subscriber cmd_vel_sub_;
  ::ros::ServiceServer reset_odometry_srv_;
  ::ros::ServiceServer reset_srv_;
  ::ros::ServiceServer clear_encoders_srv_;
};

}  // namespace serial_robot_driver::devices::base::ros
