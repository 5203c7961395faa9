#include "serial_robot_driver/ServoBusTuningConfig.h"
#include "serial_robot_driver/devices/servo_bus/ros/servo_bus_ros.h"
#include "serial_robot_driver/ros/ros_device_module.h"
#include "serial_robot_driver/ros/tuning_group_server.h"

namespace serial_robot_driver::devices::servo_bus {

namespace {

// The ~servo_bus group: the bus timing, polling and protection tunables (ServoBusTuning.cfg).
void addTuning(ros_layer::RuntimeTuning& tuning, const ::ros::NodeHandle& private_nh,
               ros_layer::RuntimeTuning::Servers& servers) {
  ros_layer::addGroupServer<ServoBusTuningConfig>(tuning, private_nh, "servo_bus", servers);
}

}  // namespace

extern const ros_layer::RosDeviceModule kRosModule{
    .name = "servo_bus",
    .make = ros_layer::makeInterface<ros::ServoBusRos>,
    .add_tuning = addTuning,
};

}  // namespace serial_robot_driver::devices::servo_bus
