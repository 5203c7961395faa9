// The echo device's parameter section (~echo/...), reached like every device's through the key
// its module declares: rows in src/devices/echo/echo_module.cpp.
#pragma once

#include "serial_robot_driver/params/device_sections.h"
#include "serial_robot_driver/params/port_params.h"

namespace serial_robot_driver::devices::echo {

struct EchoParams : params::DevicePortParams {
  /// Off unless asked for: the echo device is the tests' and changes nothing for the robot.
  EchoParams() { enabled = false; }
  /// ms an answer may take before a ping counts as timed out.
  int timeout_ms = 200;
};

/// The key of the echo device's section (DeviceModule::sections).
extern const params::SectionKey<EchoParams> kEchoSection;

}  // namespace serial_robot_driver::devices::echo
