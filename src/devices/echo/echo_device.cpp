#include "serial_robot_driver/devices/echo/echo_device.h"

#include <cstdio>

#include "serial_robot_driver/devices/echo/echo_params.h"
#include "serial_robot_driver/devices/echo/echo_status.h"

namespace serial_robot_driver::devices::echo {

EchoDevice::EchoDevice(const params::DriverParams& params, core::SerialLink& link)
    : link_(link),
      controller_(link.writer(),
                  std::chrono::milliseconds(params.section(kEchoSection).timeout_ms)) {
  link.addListener(&controller_);
}

core::Outcome EchoDevice::ping() {
  const PingResult result = controller_.ping();
  if (!result.ok) return {false, result.error};
  char text[64];
  std::snprintf(text, sizeof text, "round trip %.3f ms",
                std::chrono::duration<double, std::milli>(result.round_trip).count());
  return {true, text};
}

core::StatusReport EchoDevice::status() {
  return echoStatus(controller_.stats(), {link_.options().path, link_.connected()});
}

}  // namespace serial_robot_driver::devices::echo
