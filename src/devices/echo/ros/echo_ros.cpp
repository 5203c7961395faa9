#include "serial_robot_driver/devices/echo/ros/echo_ros.h"

#include "serial_robot_driver/ros/trigger_service.h"

namespace serial_robot_driver::devices::echo::ros {

EchoRos::EchoRos(::ros::NodeHandle& nh, EchoDevice& device)
    : ping_srv_(ros_layer::advertiseTrigger(nh, device.inputRefusals(), "echo/ping",
                                            [&device] { return device.ping(); })) {}

}  // namespace serial_robot_driver::devices::echo::ros
