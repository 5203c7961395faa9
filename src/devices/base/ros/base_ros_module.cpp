#include "serial_robot_driver/BaseTuningConfig.h"
#include "serial_robot_driver/devices/base/ros/base_ros.h"
#include "serial_robot_driver/ros/ros_device_module.h"
#include "serial_robot_driver/ros/tuning_group_server.h"

namespace serial_robot_driver::devices::base {

namespace {

std::unique_ptr<ros_layer::DeviceFrontEnd> attach(::ros::NodeHandle& nh,
                                                  const ros_layer::DriverParams& params,
                                                  core::Device& device) {
  // The core built it from kModule's make_device (base_module.cpp): a BaseDevice.
  return std::make_unique<ros::BaseRos>(nh, params, static_cast<BaseDevice&>(device));
}

// The ~base group: the wheel, speed, battery and odometry tunables (BaseTuning.cfg).
void addTuning(ros_layer::RuntimeTuning& tuning, const ::ros::NodeHandle& private_nh,
               ros_layer::RuntimeTuning::Servers& servers) {
  ros_layer::addGroupServer<BaseTuningConfig>(tuning, private_nh, "base", servers);
}

}  // namespace

extern const ros_layer::RosDeviceModule kRosModule{
    .name = "base",
    .attach = attach,
    .add_tuning = addTuning,
};

}  // namespace serial_robot_driver::devices::base
