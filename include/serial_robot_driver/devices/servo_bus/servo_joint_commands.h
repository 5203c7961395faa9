// Bus servos as joints of servo_states / servo_commands: their names ("servo_<id>") and one
// message's joint targets turned into moves, with the reason a message is refused whole.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "serial_robot_driver/devices/servo_bus/servo_bus_client.h"

namespace serial_robot_driver::devices::servo_bus {

/// The servo_states / servo_commands joint name of bus servo `id`: "servo_<id>".
std::string servoJointName(uint8_t id);
/// The bus servo id of a joint name ("servo_<id>", id 0..254), or -1 when the name is not of that
/// form (nor canonical: "servo_007" is not servo 7's name).
int servoIdFromJointName(const std::string& name);
/// "1, 3": servo ids as the messages list them; empty when there is none.
std::string servoIdList(const std::vector<uint8_t>& ids);

/// The moves of one servo_commands message, or the reason it is rejected (nothing is sent then).
struct ServoCommandBatch {
  std::vector<MoveRequest> moves;
  std::string error;  ///< non-empty: rejected, e.g. "has 2 names but 1 positions"
};
/// Positions in rad, velocities in rad/s, one per name or none at all (an entry without a
/// velocity, or 0: ROTATE with `interval_ms`; else CMD 12 by velocity).
ServoCommandBatch toServoMoves(const std::vector<std::string>& names,
                               const std::vector<double>& positions,
                               const std::vector<double>& velocities, uint16_t interval_ms);

}  // namespace serial_robot_driver::devices::servo_bus
