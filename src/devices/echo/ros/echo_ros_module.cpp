#include "serial_robot_driver/devices/echo/ros/echo_ros.h"
#include "serial_robot_driver/ros/ros_device_module.h"

namespace serial_robot_driver::devices::echo {

namespace {

std::unique_ptr<ros_layer::DeviceFrontEnd> attach(::ros::NodeHandle& nh,
                                                  const ros_layer::DriverParams& /*params*/,
                                                  core::Device& device) {
  // The core built it from kModule's make_device (echo_module.cpp): an EchoDevice.
  return std::make_unique<ros::EchoRos>(nh, static_cast<EchoDevice&>(device));
}

}  // namespace

// Nothing to tune: no add_tuning.
extern const ros_layer::RosDeviceModule kRosModule{
    .name = "echo",
    .attach = attach,
};

}  // namespace serial_robot_driver::devices::echo
