// servo/move (CMD 8 and 11..15): one request for the whole motion set, its limits (vendor SDK and
// datasheet) and the command it becomes. ROS-free, pure.
#pragma once

#include <cstdint>

#include "serial_robot_driver/devices/servo_bus/servo_bus_codec.h"
#include "serial_robot_driver/devices/servo_bus/servo_transactions.h"

namespace serial_robot_driver::devices::servo_bus {

/// One request for the whole motion set of CMD 8 and 11..15 (servo/move). The command follows from
/// the fields: velocity_dps > 0 -> by velocity (12, multi-turn 15); else accel_ms or decel_ms > 0
/// -> by interval with ramps (11 / 14); else plain (8 / 13).
struct MoveRequest {
  uint8_t id = 0;
  double angle_deg = 0.0;  ///< single-turn within +-180, multi-turn within +-368640
  bool multi_turn = false;
  uint32_t interval_ms = 0;   ///< single-turn at most 65535, multi-turn at most 4096000
  double velocity_dps = 0.0;  ///< 0: not by velocity; else 0.1 .. 750
  uint16_t accel_ms = 0;      ///< 0: not given (20, the firmware's shortest, is sent where needed)
  uint16_t decel_ms = 0;
  uint16_t power_mw = 0;  ///< 0: the servo's default limit
};

/// The command `request` asks for (see MoveRequest), with the wire's units; kInvalidArgument, and
/// `command` untouched, when a field is out of range.
ServoStatus toMoveCommand(const MoveRequest& request, MoveCommand* command);

}  // namespace serial_robot_driver::devices::servo_bus
