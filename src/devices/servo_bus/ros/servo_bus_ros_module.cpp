#include "serial_robot_driver/ServoBusTuningConfig.h"
#include "serial_robot_driver/devices/servo_bus/ros/servo_bus_ros.h"
#include "serial_robot_driver/ros/ros_device_module.h"
#include "serial_robot_driver/ros/tuning_group_server.h"

namespace serial_robot_driver::devices::servo_bus {

namespace {

std::unique_ptr<ros_layer::DeviceFrontEnd> attach(::ros::NodeHandle& nh,
                                                  const ros_layer::DriverParams& /*params*/,
                                                  core::Device& device) {
  // The core built it from kModule's make_device (servo_bus_module.cpp): a ServoBusDevice.
  return std::make_unique<ros::ServoBusRos>(nh, static_cast<ServoBusDevice&>(device));
}

// The ~servo_bus group: the bus timing, polling and protection tunables (ServoBusTuning.cfg).
void addTuning(ros_layer::RuntimeTuning& tuning, const ::ros::NodeHandle& private_nh,
               ros_layer::RuntimeTuning::Servers& servers) {
  ros_layer::addGroupServer<ServoBusTuningConfig>(tuning, private_nh, "servo_bus", servers);
}

}  // namespace

extern const ros_layer::RosDeviceModule kRosModule{
    .name = "servo_bus",
    .attach = attach,
    .add_tuning = addTuning,
};

}  // namespace serial_robot_driver::devices::servo_bus
