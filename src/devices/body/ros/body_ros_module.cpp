#include "serial_robot_driver/devices/body/body_interface.h"
#include "serial_robot_driver/ros/ros_device_module.h"

namespace serial_robot_driver::devices::body {

extern const ros_layer::RosDeviceModule kRosModule{"body", ros_layer::makeInterface<ros_layer::BodyInterface>};

}  // namespace serial_robot_driver::devices::body
