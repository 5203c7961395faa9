// The e-stop's diagnostic status ("e_stop"): engaged or released, and the motion commands it
// refused, by source.
#pragma once

#include "serial_robot_driver/core/e_stop.h"
#include "serial_robot_driver/core/status_report.h"

namespace serial_robot_driver::core {

/// The keys of the values a client of the status reads back (calibrate_base).
inline constexpr const char* kEStopEngagedKey = "engaged";          ///< "True" or "False"
inline constexpr const char* kEStopEngagementsKey = "engagements";  ///< a count

/// WARN while engaged, else OK "released".
StatusReport eStopStatus(const EStopStats& stats);

/// Logs (core/log.h) what an e_stop message that changed the e-stop did: one line, the same
/// whichever front end (ROS 1, ROS 2) the message came from.
void logEStopChange(bool engaged);

}  // namespace serial_robot_driver::core
