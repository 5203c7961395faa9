#include "serial_robot_driver/ImuTuningConfig.h"
#include "serial_robot_driver/devices/body/ros/body_ros.h"
#include "serial_robot_driver/ros/ros_device_module.h"
#include "serial_robot_driver/ros/tuning_group_server.h"

namespace serial_robot_driver::devices::body {

namespace {

std::unique_ptr<ros_layer::DeviceFrontEnd> attach(::ros::NodeHandle& nh,
                                                  const ros_layer::DriverParams& params,
                                                  core::Device& device) {
  // The core built it from kModule's make_device (body_module.cpp): a BodyDevice.
  return std::make_unique<ros::BodyRos>(nh, params, static_cast<BodyDevice&>(device));
}

// The board's IMU scales are the ~imu group (ImuTuning.cfg), named like their parameters.
void addTuning(ros_layer::RuntimeTuning& tuning, const ::ros::NodeHandle& private_nh,
               ros_layer::RuntimeTuning::Servers& servers) {
  ros_layer::addGroupServer<ImuTuningConfig>(tuning, private_nh, "imu", servers);
}

}  // namespace

extern const ros_layer::RosDeviceModule kRosModule{
    .name = "body",
    .attach = attach,
    .add_tuning = addTuning,
};

}  // namespace serial_robot_driver::devices::body
