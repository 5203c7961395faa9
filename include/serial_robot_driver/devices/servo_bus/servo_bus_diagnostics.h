// The servo bus's statuses: the bus's own ("servo_bus": device::ServoBusStatus over a snapshot of
// the client, the worker and the settings in force) and one per polled servo ("servo_bus servo
// <id>": device::servoHealthStatus with its identity).
#pragma once

#include <cstdint>

#include "serial_robot_driver/core/serial_link.h"
#include "serial_robot_driver/core/status_report.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus_status.h"

namespace serial_robot_driver::devices::servo_bus {

class ServoBusDiagnostics {
 public:
  /// `bus` and `link` must outlive this object.
  ServoBusDiagnostics(ServoBus& bus, const core::SerialLink& link) : bus_(bus), link_(link) {}

  /// The bus's status; `commands_rejected`: servo_commands messages refused so far. servo_states
  /// asked vs achieved since the last call, so one caller only (the diagnostics thread).
  core::StatusReport busStatus(uint64_t commands_rejected);
  /// Servo `id`'s readings against its own limits (an offline servo is an ERROR), its identity
  /// and a WARN for each setting that does not fit. Any thread.
  core::StatusReport servoStatus(uint8_t id) const;

 private:
  ServoBus& bus_;
  const core::SerialLink& link_;
  ServoBusStatus status_;
};

}  // namespace serial_robot_driver::devices::servo_bus
