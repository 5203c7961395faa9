// The diagnostic status of one serial port ("port <path>"): connected or why not, the byte and
// frame counters, the framer's errors and the USB adapter's latency_timer.
#pragma once

#include "serial_robot_driver/core/serial_link.h"
#include "serial_robot_driver/core/status_report.h"

namespace serial_robot_driver::core {

/// OK "connected" (WARN when the adapter's latency_timer is above 1 ms), ERROR when not connected.
StatusReport linkStatus(const LinkStats& stats, const SerialLinkOptions& options);

}  // namespace serial_robot_driver::core
