// The echo device as a device of the driver, ROS-free: the controller on its port, its status,
// and its one input, ping(), which every front end calls the same way.
#pragma once

#include "serial_robot_driver/core/device.h"
#include "serial_robot_driver/core/outcome.h"
#include "serial_robot_driver/core/serial_link.h"
#include "serial_robot_driver/devices/echo/echo_controller.h"

namespace serial_robot_driver::devices::echo {

class EchoDevice : public core::Device {
 public:
  /// Registers the controller on `link` (before the link starts); `link` must outlive this.
  EchoDevice(const params::DriverParams& params, core::SerialLink& link);

  /// One round trip (echo/ping): its time in the message, or why it failed.
  core::Outcome ping();

  void start() override {}
  void shutdown() override {}
  core::StatusReport status() override;

 private:
  core::SerialLink& link_;
  EchoController controller_;
};

}  // namespace serial_robot_driver::devices::echo
