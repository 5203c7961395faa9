// The echo device's diagnostic status ("echo"): the link, the last ping's outcome and the
// controller's counters. ROS-free; the ROS layer copies it into /diagnostics.
#pragma once

#include "serial_robot_driver/core/status_report.h"
#include "serial_robot_driver/devices/echo/echo_controller.h"

namespace serial_robot_driver::devices::echo {

/// ERROR while the port is closed, WARN when the last ping had no answer, else OK.
core::StatusReport echoStatus(const EchoStats& stats, const core::PortState& port);

}  // namespace serial_robot_driver::devices::echo
