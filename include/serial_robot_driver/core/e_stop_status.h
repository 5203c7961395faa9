// The e-stop's diagnostic status ("e_stop"): engaged or released, and the motion commands it
// refused, by source.
#pragma once

#include "serial_robot_driver/core/e_stop.h"
#include "serial_robot_driver/core/status_report.h"

namespace serial_robot_driver::core {

/// WARN while engaged, else OK "released".
StatusReport eStopStatus(const EStopStats& stats);

/// Logs (core/log.h) what an e_stop message that changed the e-stop did: one line, the same
/// whichever front end (ROS 1, ROS 2) the message came from.
void logEStopChange(bool engaged);

}  // namespace serial_robot_driver::core
