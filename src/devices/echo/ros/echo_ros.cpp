#include "serial_robot_driver/devices/echo/ros/echo_ros.h"

#include <cstdio>

#include "serial_robot_driver/devices/echo/echo_params.h"
#include "serial_robot_driver/devices/echo/echo_status.h"
#include "serial_robot_driver/ros/guarded_callbacks.h"

namespace serial_robot_driver::devices::echo::ros {

EchoRos::EchoRos(::ros::NodeHandle& nh, const ros_layer::DriverParams& params,
                 core::SerialLink& link)
    : link_(link),
      controller_(link.writer(),
                  std::chrono::milliseconds(params.section(kEchoSection).timeout_ms)) {
  ping_srv_ = ros_layer::advertiseGuarded(nh, inputRefusals(), "echo/ping", &EchoRos::onPing, this);
  link.addListener(&controller_);
}

void EchoRos::shutdown() { ping_srv_.shutdown(); }

bool EchoRos::onPing(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& response) {
  const PingResult result = controller_.ping();
  response.success = result.ok;
  if (result.ok) {
    char text[64];
    std::snprintf(text, sizeof text, "round trip %.3f ms",
                  std::chrono::duration<double, std::milli>(result.round_trip).count());
    response.message = text;
  } else {
    response.message = result.error;
  }
  return true;
}

core::StatusReport EchoRos::status() {
  return echoStatus(controller_.stats(), {link_.options().path, link_.connected()});
}

}  // namespace serial_robot_driver::devices::echo::ros
