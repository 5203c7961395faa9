#include "serial_robot_driver/devices/servo_bus/servo_identity.h"

#include <algorithm>
#include <cstdio>

#include "serial_robot_driver/devices/servo_bus/servo_bus_client.h"

namespace serial_robot_driver::devices::servo_bus {

namespace {

std::string decidegrees(int64_t value) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.1f", static_cast<double>(value) / 10.0);
  return text;
}

/// Reads `names` in order at `priority` into `values`; the first failure.
ServoStatus readAll(ServoBusClient& client, uint8_t id, BusPriority priority,
                    const std::vector<const char*>& names, std::vector<int64_t>* values) {
  values->clear();
  for (const char* name : names) {
    ServoParamValue value;
    const ServoStatus status = client.readParam(id, name, &value, priority);
    if (!status.ok()) return status;
    values->push_back(value.value);
  }
  return {};
}

}  // namespace

std::vector<std::string> identityWarnings(uint8_t id, const ServoIdentity& identity,
                                          const ServoIdentityChecks& checks) {
  const std::string servo = "servo " + std::to_string(id) + ": ";
  std::vector<std::string> warnings;
  if (checks.expected_type != 0 && identity.servo_type != checks.expected_type) {
    warnings.push_back(servo + "servo_type " + std::to_string(identity.servo_type) +
                       " is not the expected " + std::to_string(checks.expected_type) +
                       " (~servo_bus/expected_type): another model, driven as if it were the "
                       "configured one");
  }
  if (checks.expected_firmware != 0 && identity.firmware_version != checks.expected_firmware) {
    warnings.push_back(servo + "firmware_version " + std::to_string(identity.firmware_version) +
                       " is not the expected " + std::to_string(checks.expected_firmware) +
                       " (~servo_bus/expected_firmware)");
  }
  if (identity.response_switch != 0) {
    warnings.push_back(servo + "response_switch is " + std::to_string(identity.response_switch) +
                       ": motion commands are queued, so a stop cannot interrupt a motion "
                       "already queued, and every motion command is answered, which takes bus "
                       "time (write response_switch 0 to fix)");
  }
  const bool joint =
      std::find(checks.joint_ids.begin(), checks.joint_ids.end(), id) != checks.joint_ids.end();
  if (joint && identity.angle_limit_on &&
      (identity.angle_limit_low > kJointRangeLow || identity.angle_limit_high < kJointRangeHigh)) {
    warnings.push_back(servo + "angle limits " + describeAngleLimits(identity) +
                       " are narrower than its joint's range " + decidegrees(kJointRangeLow) +
                       ".." + decidegrees(kJointRangeHigh) +
                       " deg: the servo stops short of targets beyond them");
  }
  return warnings;
}

std::string describeIdentity(const ServoIdentity& identity) {
  return "servo_type " + std::to_string(identity.servo_type) + ", firmware_version " +
         std::to_string(identity.firmware_version) + ", serial_number " +
         std::to_string(identity.serial_number) + ", response_switch " +
         std::to_string(identity.response_switch);
}

std::string describeAngleLimits(const ServoIdentity& identity) {
  if (!identity.angle_limit_on) return "off";
  return decidegrees(identity.angle_limit_low) + ".." + decidegrees(identity.angle_limit_high) +
         " deg";
}

ServoStatus readServoIdentity(ServoBusClient& client, uint8_t id, BusPriority priority,
                              bool with_limits, ServoIdentity* identity) {
  std::vector<int64_t> values;
  ServoStatus status = readAll(
      client, id, priority,
      {"servo_type", "firmware_version", "serial_number", "response_switch", "angle_limit_switch"},
      &values);
  if (!status.ok()) return status;
  ServoIdentity read;
  // The client decoded each value with its parameter's wire type, so each fits its field.
  read.servo_type = static_cast<uint16_t>(values[0]);
  read.firmware_version = static_cast<uint16_t>(values[1]);
  read.serial_number = static_cast<uint32_t>(values[2]);
  read.response_switch = static_cast<uint8_t>(values[3]);
  read.angle_limit_on = values[4] != 0;
  if (read.angle_limit_on) {
    status = readAll(client, id, priority, {"angle_limit_low", "angle_limit_high"}, &values);
    if (!status.ok()) return status;
    read.angle_limit_low = values[0];
    read.angle_limit_high = values[1];
  }
  if (with_limits) {
    status = readAll(
        client, id, priority,
        {"over_volt_low", "over_volt_high", "over_temperature", "over_power", "over_current"},
        &values);
    if (!status.ok()) return status;
    read.limits = {values[0], values[1], values[2], values[3], values[4]};
    read.limits_known = true;
  }
  *identity = read;
  return {};
}

ServoStatus readServoInfo(ServoBusClient& client, uint8_t id, const ServoIdentityChecks& checks,
                          ServoIdentity* identity) {
  ServoIdentity read;
  const ServoStatus status = readServoIdentity(client, id, BusPriority::kCaller, true, &read);
  if (!status.ok()) {
    return {status.error,
            "servo " + std::to_string(id) + "'s identity could not be read: " + status.message};
  }
  *identity = read;
  const ServoLimits& limits = read.limits;
  std::string message = "servo " + std::to_string(id) + ": " + describeIdentity(read) +
                        ", angle limits " + describeAngleLimits(read) + ", over_volt_low " +
                        std::to_string(limits.over_volt_low_mv) + " mV, over_volt_high " +
                        std::to_string(limits.over_volt_high_mv) + " mV, over_temperature " +
                        std::to_string(limits.over_temperature_c) + " degC, over_power " +
                        std::to_string(limits.over_power_mw) + " mW, over_current " +
                        std::to_string(limits.over_current_ma) + " mA";
  const std::vector<std::string> warnings = identityWarnings(id, read, checks);
  for (const std::string& warning : warnings) message += "; WARNING " + warning;
  return {ServoError::kOk, message};
}

}  // namespace serial_robot_driver::devices::servo_bus
