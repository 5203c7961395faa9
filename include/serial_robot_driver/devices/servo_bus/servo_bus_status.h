// The servo bus's diagnostic statuses: "servo_bus" (transactions, the poll's asked vs achieved
// rate, the e-stop's lock and the stops not yet confirmed) and "servo_bus servo <id>", one per
// polled servo (its health against its own limits, its identity and the settings the driver
// depends on).
#pragma once

#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

#include "serial_robot_driver/core/status_report.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus_client.h"
#include "serial_robot_driver/devices/servo_bus/servo_joint_commands.h"

namespace serial_robot_driver::devices::servo_bus {

/// Servo `id`'s status at ~servo_bus/health_rate `health_rate` from its health report (null: not
/// polled yet): its readings and limits, WARN within 10 % of a limit, ERROR beyond it, when it
/// does not answer or when ~servo_bus/protect relaxed it.
core::StatusReport servoHealthStatus(uint8_t id, double health_rate,
                                     const ServoHealthReport* report);
/// Adds servo's identity to its status: servo_type, firmware_version, serial_number,
/// response_switch and angle limits, and a WARN naming each setting that does not fit the
/// configuration (identityWarnings). Null or not known yet: "not read yet".
void addServoIdentity(const ServoIdentityReport* identity, core::StatusReport* status);

/// What the "servo_bus" status is made of, read from the bus at one diagnostics update.
struct ServoBusSnapshot {
  core::PortState port;
  ServoBusStats stats;      ///< the client's
  ServoBusOptions options;  ///< the client's, in force
  ServoBusWorkerStats worker;
  std::vector<uint8_t> moving_ids;
  bool motion_locked = false;  ///< e_stop
  uint64_t motion_refused_at_write = 0;
  std::vector<PendingStopReport> pending_stops;
  ServoBusConfig in_force;         ///< ServoBus::settings()
  uint64_t commands_rejected = 0;  ///< servo_commands messages rejected
};

/// Keeps the window of the asked vs achieved poll rate between updates (one thread).
class ServoBusStatus {
 public:
  /// The achieved rate is measured over at least this long, so one slow transaction (a silent
  /// servo's timeout, a long service call) does not flag a line that keeps up on average.
  static constexpr double kRateWindowS = 2.0;
  /// A rate below this share of the asked one is a WARN (the rest is the window's own jitter).
  static constexpr double kRateSlack = 0.9;

  core::StatusReport update(const ServoBusSnapshot& bus, std::chrono::steady_clock::time_point now);

 private:
  /// The state_rate asked against the angle reads achieved over the last window.
  void addPollRate(const ServoBusSnapshot& bus, std::chrono::steady_clock::time_point now,
                   core::StatusReport* status);

  uint64_t polls_at_last_check_ = 0;
  std::chrono::steady_clock::time_point last_rate_check_{};
  double achieved_rate_ = -1.0;  ///< reads/s over the last window; < 0: none yet
};

}  // namespace serial_robot_driver::devices::servo_bus
