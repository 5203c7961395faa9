#include "serial_robot_driver/devices/base/base_interface.h"
#include "serial_robot_driver/ros/ros_device_module.h"

namespace serial_robot_driver::devices::base {

extern const ros_layer::RosDeviceModule kRosModule{"base", ros_layer::makeInterface<ros_layer::BaseInterface>};

}  // namespace serial_robot_driver::devices::base
