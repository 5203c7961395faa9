#include "serial_robot_driver/devices/servo_bus/servo_joint_commands.h"

#include <algorithm>
#include <cmath>

namespace serial_robot_driver::devices::servo_bus {

namespace {
constexpr double kDegreesPerRadian = 180.0 / M_PI;
constexpr int kMaxBusId = 254;  // 255 is the broadcast address
// A caller's absurdly long name is cut in the message, not echoed in full.
constexpr std::size_t kNameShownChars = 40;
}  // namespace

std::string servoJointName(uint8_t id) { return "servo_" + std::to_string(id); }

int servoIdFromJointName(const std::string& name) {
  static const std::string kPrefix = "servo_";
  if (name.size() <= kPrefix.size() || name.size() > kPrefix.size() + 3 ||
      name.compare(0, kPrefix.size(), kPrefix) != 0) {
    return -1;
  }
  int id = 0;
  for (std::size_t i = kPrefix.size(); i < name.size(); ++i) {
    if (name[i] < '0' || name[i] > '9') return -1;
    id = id * 10 + (name[i] - '0');
  }
  // "servo_007" is not the canonical name of servo 7: refuse rather than guess.
  if (name != servoJointName(static_cast<uint8_t>(std::min(id, 255)))) return -1;
  return id <= kMaxBusId ? id : -1;
}

std::string servoIdList(const std::vector<uint8_t>& ids) {
  std::string text;
  for (uint8_t id : ids) text += (text.empty() ? "" : ", ") + std::to_string(id);
  return text;
}

ServoCommandBatch toServoMoves(const std::vector<std::string>& names,
                               const std::vector<double>& positions,
                               const std::vector<double>& velocities, uint16_t interval_ms) {
  ServoCommandBatch batch;
  if (positions.size() != names.size()) {
    batch.error = "has " + std::to_string(names.size()) + " names but " +
                  std::to_string(positions.size()) + " positions";
    return batch;
  }
  if (!velocities.empty() && velocities.size() != names.size()) {
    batch.error = "has " + std::to_string(names.size()) + " names but " +
                  std::to_string(velocities.size()) + " velocities (give none or one per name)";
    return batch;
  }
  for (std::size_t i = 0; i < names.size(); ++i) {
    const int id = servoIdFromJointName(names[i]);
    if (id < 0) {
      batch.error = "names '" + names[i].substr(0, kNameShownChars) +
                    "', which is not a bus servo (expected servo_<id>, id 0..254)";
      break;
    }
    const double position = positions[i];
    const double velocity = velocities.empty() ? 0.0 : velocities[i];
    if (!std::isfinite(position) || !std::isfinite(velocity)) {
      batch.error = "has a non-finite position or velocity for " + names[i];
      break;
    }
    MoveRequest move;
    move.id = static_cast<uint8_t>(id);
    move.angle_deg = position * kDegreesPerRadian;
    // The sign of the motion is the target's; a velocity is a speed.
    move.velocity_dps = std::fabs(velocity) * kDegreesPerRadian;
    move.interval_ms = interval_ms;
    batch.moves.push_back(move);
  }
  if (!batch.error.empty()) batch.moves.clear();
  return batch;
}

}  // namespace serial_robot_driver::devices::servo_bus
