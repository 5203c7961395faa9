#include "serial_robot_driver/devices/echo/echo_interface.h"
#include "serial_robot_driver/ros/ros_device_module.h"

namespace serial_robot_driver::devices::echo {

extern const ros_layer::RosDeviceModule kRosModule{
    "echo", ros_layer::makeInterface<ros_layer::EchoInterface>, nullptr /* nothing to tune */};

}  // namespace serial_robot_driver::devices::echo
