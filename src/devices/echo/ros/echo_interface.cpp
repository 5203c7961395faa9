#include "serial_robot_driver/devices/echo/echo_interface.h"

#include <cstdio>

#include "serial_robot_driver/devices/echo/echo_params.h"
#include "serial_robot_driver/devices/echo/echo_status.h"
#include "serial_robot_driver/ros/guarded_callbacks.h"

namespace serial_robot_driver::ros_layer {

EchoInterface::EchoInterface(ros::NodeHandle& nh, const DriverParams& params,
                             device::SerialLink& link)
    : link_(link),
      controller_(link.writer(),
                  std::chrono::milliseconds(params.section(params::kEchoSection).timeout_ms)) {
  ping_srv_ = advertiseGuarded(nh, inputRefusals(), "echo/ping", &EchoInterface::onPing, this);
  link.addListener(&controller_);
}

void EchoInterface::shutdown() { ping_srv_.shutdown(); }

bool EchoInterface::onPing(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& response) {
  const device::PingResult result = controller_.ping();
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

device::StatusReport EchoInterface::status() {
  return device::echoStatus(controller_.stats(), {link_.options().path, link_.connected()});
}

}  // namespace serial_robot_driver::ros_layer
