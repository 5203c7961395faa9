// The echo device's parameter section (~echo/...), kept in DriverParams::sections (it has no
// member there): rows in src/devices/echo/echo_module.cpp.
#pragma once

#include "serial_robot_driver/params/port_params.h"

namespace serial_robot_driver::params {

struct EchoParams : DevicePortParams {
  /// Off unless asked for: the echo device is the tests' and changes nothing for the robot.
  EchoParams() { enabled = false; }
  /// ms an answer may take before a ping counts as timed out.
  int timeout_ms = 200;
};

}  // namespace serial_robot_driver::params
