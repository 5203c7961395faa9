// ROS front end of the echo device (devices::echo::EchoDevice): the service echo/ping
// (std_srvs/Trigger: one round trip, its time in the message).
#pragma once

#include <ros/ros.h>

#include "serial_robot_driver/devices/echo/echo_device.h"
#include "serial_robot_driver/ros/device_front_end.h"
#include "serial_robot_driver/ros/driver_params.h"

namespace serial_robot_driver::devices::echo::ros {

class EchoRos : public ros_layer::DeviceFrontEnd {
 public:
  /// Advertises echo/ping. `device` must outlive this object.
  EchoRos(::ros::NodeHandle& nh, EchoDevice& device);
  /// Stops taking pings.
  void shutdown() override { ping_srv_.shutdown(); }

 private:
  ::ros::ServiceServer ping_srv_;
};

}  // namespace serial_robot_driver::devices::echo::ros
