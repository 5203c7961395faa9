#include "serial_robot_driver/devices/echo/echo_interface.h"
#include "serial_robot_driver/ros/ros_device_module.h"

namespace serial_robot_driver::devices::echo {

// Nothing to tune: no add_tuning.
extern const ros_layer::RosDeviceModule kRosModule{
    .name = "echo",
    .make = ros_layer::makeInterface<ros_layer::EchoInterface>,
};

}  // namespace serial_robot_driver::devices::echo
