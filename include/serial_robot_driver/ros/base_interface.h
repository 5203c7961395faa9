// ROS face of the AP1 base: cmd_vel in; wheel_command, battery and diagnostics out; base/reset and
// base/clear_encoders services. The control loop itself is device::BaseController's thread.
#pragma once

#include <memory>

#include <diagnostic_updater/diagnostic_updater.h>
#include <geometry_msgs/Twist.h>
#include <ros/ros.h>
#include <std_srvs/Trigger.h>

#include "serial_robot_driver/device/base_controller.h"
#include "serial_robot_driver/ros/conversions.h"
#include "serial_robot_driver/ros/device_interface.h"
#include "serial_robot_driver/ros/driver_params.h"

namespace serial_robot_driver::ros_layer {

device::BaseConfig makeBaseConfig(const DriverParams& params);

class BaseInterface : public DeviceInterface {
 public:
  /// Registers the controller on `link` (before the link starts), advertises the topics and
  /// services and adds the "base" diagnostic task. `link` must outlive this object.
  BaseInterface(ros::NodeHandle& nh, const DriverParams& params, device::SerialLink& link,
                diagnostic_updater::Updater& diagnostics);
  /// Starts the control loop (after the links are started).
  void start() override { controller_.start(); }
  /// Stops the loop and writes a zero-speed frame (before the port closes).
  void shutdown() override { controller_.stop(); }
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) override;

 private:
  device::BaseEvents events();
  void onCmdVel(const geometry_msgs::Twist::ConstPtr& msg);
  bool onReset(std_srvs::Trigger::Request& req, std_srvs::Trigger::Response& res);
  bool onClearEncoders(std_srvs::Trigger::Request& req, std_srvs::Trigger::Response& res);

  device::SerialLink& link_;
  ArrivalStamps arrival_stamps_;  // before controller_: its events use it
  device::BaseController controller_;
  ros::Publisher wheel_command_pub_;
  ros::Publisher battery_pub_;
  ros::Subscriber cmd_vel_sub_;
  ros::ServiceServer reset_srv_;
  ros::ServiceServer clear_encoders_srv_;
};

}  // namespace serial_robot_driver::ros_layer
