// The base's diagnostic status ("base"): the link, the base's own replies, the battery against
// ~base/battery_{warn,error}_percent, the e-stop, the odom heading source and the counters.
#pragma once

#include "serial_robot_driver/core/status_report.h"
#include "serial_robot_driver/devices/base/base_controller.h"

namespace serial_robot_driver::devices::base {

/// A timeout error (FF) from a running base stays a WARN this long (s).
constexpr double kRecentTimeoutErrorS = 10.0;

/// ~base/battery_warn_percent and battery_error_percent: a battery below them is a WARN / ERROR.
struct BatteryLimits {
  int warn_percent = 0;
  int error_percent = 0;
};

/// OK "driving", else every problem: port down or base silent (ERROR), a recent FF, the e-stop or
/// odom without the IMU's heading (WARN), the battery against `limits`.
core::StatusReport baseStatus(const BaseStats& stats, const core::PortState& port,
                              BatteryLimits limits);

}  // namespace serial_robot_driver::devices::base
