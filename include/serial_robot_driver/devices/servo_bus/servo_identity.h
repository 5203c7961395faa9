// A bus servo's identity (servo_type, firmware_version, serial_number) and the settings the
// driver depends on (response_switch, the angle limits), read with READ_DATA, and the checks that
// say when they do not fit what the driver expects. ROS-free: device::ServoPoller reads them once
// per configured servo when it first answers, the servo/info service reads them on request.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "serial_robot_driver/devices/servo_bus/bus_mutex.h"
#include "serial_robot_driver/devices/servo_bus/servo_health.h"
#include "serial_robot_driver/devices/servo_bus/servo_transactions.h"

namespace serial_robot_driver::devices::servo_bus {

class ServoBusClient;

/// What READ_DATA says of a servo's identity and of the settings the driver depends on.
struct ServoIdentity {
  uint16_t servo_type = 0;
  uint16_t firmware_version = 0;
  uint32_t serial_number = 0;
  /// 0: a motion command interrupts the one running and is not answered; 1: motion commands are
  /// queued behind each other and each is answered when it completes.
  uint8_t response_switch = 0;
  bool angle_limit_on = false;   ///< angle_limit_switch: the servo clamps its moves
  int64_t angle_limit_low = 0;   ///< 0.1 deg, read only while angle_limit_on
  int64_t angle_limit_high = 0;  ///< 0.1 deg, read only while angle_limit_on
  bool limits_known = false;     ///< `limits` read (readServoIdentity with `with_limits`)
  ServoLimits limits;            ///< the protection limits, as the health poll reads them
};

/// What every configured servo should be; 0 is not checked (~servo_bus/expected_type,
/// ~servo_bus/expected_firmware).
struct ServoIdentityChecks {
  uint16_t expected_type = 0;
  uint16_t expected_firmware = 0;
  /// Servos driven as joints (~servo_bus/joint_ids): trajectories and servo_commands command them
  /// anywhere in the single-turn range, so angle limits narrower than it defeat them.
  std::vector<uint8_t> joint_ids;
};

/// The single-turn range a joint servo is commanded within, in 0.1 deg (servo/move's limits).
constexpr int64_t kJointRangeLow = -1800;
constexpr int64_t kJointRangeHigh = 1800;

/// One sentence per setting that does not fit `checks`, each naming servo `id` and saying what it
/// costs: servo_type or firmware_version other than expected, response_switch 1, angle limits
/// narrower than a joint's range. Empty when all fit.
std::vector<std::string> identityWarnings(uint8_t id, const ServoIdentity& identity,
                                          const ServoIdentityChecks& checks);

/// "servo_type 257, firmware_version 258, serial_number 1397882883, response_switch 0".
std::string describeIdentity(const ServoIdentity& identity);
/// "off", or "-90.0..90.0 deg".
std::string describeAngleLimits(const ServoIdentity& identity);

/// READ_DATA of servo_type, firmware_version, serial_number, response_switch, angle_limit_switch
/// and, when it is on, angle_limit_low and angle_limit_high; with `with_limits` the five
/// protection limits too. Each read at `priority` (kBackground: the bus is taken only while no
/// caller waits, so a service or a stop never waits for more than one read). The first failure
/// ends the reads and is returned; `identity` is complete only when it returns ok.
ServoStatus readServoIdentity(ServoBusClient& client, uint8_t id, BusPriority priority,
                              bool with_limits, ServoIdentity* identity);

/// servo/info: readServoIdentity with the protection limits, as a caller (any id, configured or
/// not; it moves nothing, so the e-stop allows it). Its message says what was read, the angle and
/// protection limits and every identityWarnings() sentence; on failure, which servo did not answer.
ServoStatus readServoInfo(ServoBusClient& client, uint8_t id, const ServoIdentityChecks& checks,
                          ServoIdentity* identity);

/// A configured servo's identity as the poll read it.
struct ServoIdentityReport {
  uint8_t id = 0;
  bool known = false;  ///< read once the servo first answered
  ServoIdentity identity;
  std::vector<std::string> warnings;  ///< identityWarnings() when it was read
};

}  // namespace serial_robot_driver::devices::servo_bus
