#include "serial_robot_driver/ImuTuningConfig.h"
#include "serial_robot_driver/devices/body/ros/body_ros.h"
#include "serial_robot_driver/ros/ros_device_module.h"
#include "serial_robot_driver/ros/tuning_group_server.h"

namespace serial_robot_driver::devices::body {

namespace {

// The board's IMU scales are the ~imu group (ImuTuning.cfg), named like their parameters.
void addTuning(ros_layer::RuntimeTuning& tuning, const ::ros::NodeHandle& private_nh,
               ros_layer::RuntimeTuning::Servers& servers) {
  ros_layer::addGroupServer<ImuTuningConfig>(tuning, private_nh, "imu", servers);
}

}  // namespace

extern const ros_layer::RosDeviceModule kRosModule{
    .name = "body",
    .make = ros_layer::makeInterface<ros::BodyRos>,
    .add_tuning = addTuning,
};

}  // namespace serial_robot_driver::devices::body
