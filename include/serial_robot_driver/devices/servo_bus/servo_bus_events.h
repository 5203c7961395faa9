// What a device::ServoBus reports: the hooks it calls on its worker thread, and the snapshots
// (health, pending stops, stats) its callers read. ROS-free.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "serial_robot_driver/core/serial_link.h"
#include "serial_robot_driver/devices/servo_bus/servo_health.h"
#include "serial_robot_driver/devices/servo_bus/servo_identity.h"
#include "serial_robot_driver/devices/servo_bus/servo_move.h"
#include "serial_robot_driver/devices/servo_bus/servo_transactions.h"

namespace serial_robot_driver::devices::servo_bus {

/// The health of one polled servo (health_rate > 0).
struct ServoHealthReport {
  uint8_t id = 0;
  bool polled = false;        ///< at least one health poll finished (answered or not)
  bool online = false;        ///< the last health poll was answered
  std::string last_error;     ///< why the last poll failed
  bool limits_known = false;  ///< the servo's limits, read once when it first answered
  ServoLimits limits;
  ServoReadings readings;  ///< valid once a poll was answered
  HealthAssessment assessment;
  bool overheated = false;  ///< protect: relaxed, its moves refused
};

/// One polled angle.
struct ServoAngleSample {
  uint8_t id = 0;
  double angle_deg = 0.0;
  core::Clock::time_point arrival;  ///< when the answer's last byte was read
};

/// What the bus reports; every hook may be empty.
struct ServoBusEvents {
  std::function<void(const ServoAngleSample&)> on_angle;
  /// A polled servo stopped answering (once, until it answers again); asked again after `backoff`.
  std::function<void(uint8_t id, const ServoStatus& status, std::chrono::milliseconds backoff)>
      on_servo_silent;
  std::function<void(const MoveRequest& move, const ServoStatus& status)> on_move_failed;
  /// protect: servo `report.id` was relaxed for its temperature (`overheated`), or has cooled.
  std::function<void(const ServoHealthReport& report)> on_overheat;
  /// A stop of servo `id`: ok once the servo is seen at rest after it; an error when an attempt
  /// failed (it is retried) or, at shutdown, when it could not be confirmed in time.
  std::function<void(uint8_t id, const ServoStatus& status)> on_stop;
  /// A polled servo's identity was read (once per servo, when it first answered); its warnings
  /// say what does not fit the configuration.
  std::function<void(const ServoIdentityReport& report)> on_identity;
};

/// A stop not yet known to have reached its servo.
struct PendingStopReport {
  uint8_t id = 0;
  int written = 0;  ///< times the stop went out so far
  std::string why;  ///< what is still missing: written, answered, seen at rest
};

struct ServoBusWorkerStats {
  uint64_t angles_polled = 0;        ///< on_angle reports
  uint64_t moves_sent = 0;           ///< queued moves written
  uint64_t moves_failed = 0;         ///< queued moves the client refused or could not write
  uint64_t moves_replaced = 0;       ///< queued moves replaced by a newer target of the same servo
  std::vector<uint8_t> offline_ids;  ///< polled servos in back-off
  /// Angle reads per second the schedule asks for: the poll rate in force times the polled
  /// servos not in back-off. What the line delivers is angles_polled over time.
  double asked_poll_rate = 0.0;
};

}  // namespace serial_robot_driver::devices::servo_bus
