#include "serial_robot_driver/devices/servo_bus/servo_bus_interface.h"
#include "serial_robot_driver/ros/ros_device_module.h"

namespace serial_robot_driver::devices::servo_bus {

extern const ros_layer::RosDeviceModule kRosModule{"servo_bus", ros_layer::makeInterface<ros_layer::ServoBusInterface>};

}  // namespace serial_robot_driver::devices::servo_bus
