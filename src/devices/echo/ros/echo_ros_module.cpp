#include "serial_robot_driver/devices/echo/ros/echo_ros.h"
#include "serial_robot_driver/ros/ros_device_module.h"

namespace serial_robot_driver::devices::echo {

// Nothing to tune: no add_tuning.
extern const ros_layer::RosDeviceModule kRosModule{
    .name = "echo",
    .make = ros_layer::makeInterface<ros::EchoRos>,
};

}  // namespace serial_robot_driver::devices::echo
