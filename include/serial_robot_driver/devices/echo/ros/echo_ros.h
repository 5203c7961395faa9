// ROS face of the echo device: the service echo/ping (std_srvs/Trigger: one round trip, its time
// in the message) and one diagnostic status with the controller's counters.
#pragma once

#include <ros/ros.h>
#include <std_srvs/Trigger.h>

#include "serial_robot_driver/devices/echo/echo_controller.h"
#include "serial_robot_driver/ros/device_interface.h"
#include "serial_robot_driver/ros/driver_params.h"

namespace serial_robot_driver::devices::echo::ros {

class EchoRos : public ros_layer::DeviceInterface {
 public:
  /// Registers the controller on `link` (before the link starts) and advertises echo/ping.
  EchoRos(::ros::NodeHandle& nh, const ros_layer::DriverParams& params, core::SerialLink& link);

  void start() override {}
  /// Stops taking pings.
  void shutdown() override;
  core::StatusReport status() override;

 private:
  bool onPing(std_srvs::Trigger::Request& request, std_srvs::Trigger::Response& response);

  core::SerialLink& link_;
  EchoController controller_;
  ::ros::ServiceServer ping_srv_;
};

}  // namespace serial_robot_driver::devices::echo::ros
