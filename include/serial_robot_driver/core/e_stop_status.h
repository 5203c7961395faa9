// The e-stop's diagnostic status ("e_stop"): engaged or released, and the motion commands it
// refused, by source.
#pragma once

#include "serial_robot_driver/core/e_stop.h"
#include "serial_robot_driver/core/status_report.h"

namespace serial_robot_driver::core {

/// WARN while engaged, else OK "released".
StatusReport eStopStatus(const EStopStats& stats);

}  // namespace serial_robot_driver::core
