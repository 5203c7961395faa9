#include "serial_robot_driver/devices/servo_bus/servo_move.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "servo_bus_text.h"

namespace serial_robot_driver::device {

namespace servo = protocol::servo;
using servo::Command;
using namespace servo_text;  // NOLINT: the shared sentences of every servo operation

namespace {

// servo/move limits (vendor SDK and datasheet).
constexpr double kMaxSingleTurnDeg = 180.0;
constexpr double kMaxMultiTurnDeg = 368640.0;  // 1024 turns
constexpr double kMaxVelocityDps = 750.0;
constexpr double kMinVelocityDps = 0.1;  // the wire unit; anything less is sent as 0
constexpr uint16_t kMinRampMs = 20;      // the firmware's shortest ramp
constexpr uint32_t kMaxMultiTurnIntervalMs = 4096000;

}  // namespace

ServoStatus toMoveCommand(const MoveRequest& request, servo::MoveCommand* out) {
  const auto invalid = [](const std::string& text) {
    return fail(ServoError::kInvalidArgument, text);
  };
  if (!std::isfinite(request.angle_deg)) return invalid("angle_deg is not a finite number");
  if (!std::isfinite(request.velocity_dps)) return invalid("velocity_dps is not a finite number");
  const double max_angle = request.multi_turn ? kMaxMultiTurnDeg : kMaxSingleTurnDeg;
  if (std::fabs(request.angle_deg) > max_angle) {
    return invalid("angle_deg " + formatNumber(request.angle_deg) + " is out of range +-" +
                   formatNumber(max_angle) + " deg for a " +
                   (request.multi_turn ? "multi-turn" : "single-turn") + " move");
  }
  if (request.velocity_dps < 0) {
    return invalid("velocity_dps " + formatNumber(request.velocity_dps) +
                   " is negative (0: not by velocity; the sign of the motion is the angle's)");
  }
  const bool by_velocity = request.velocity_dps > 0;
  const bool with_ramps = by_velocity || request.accel_ms > 0 || request.decel_ms > 0;
  if (by_velocity && request.velocity_dps > kMaxVelocityDps) {
    return invalid("velocity_dps " + formatNumber(request.velocity_dps) +
                   " is above the servo's 750 deg/s");
  }
  if (by_velocity && request.velocity_dps < kMinVelocityDps) {
    return invalid("velocity_dps " + formatNumber(request.velocity_dps) +
                   " is below 0.1 deg/s, the unit on the wire");
  }
  for (const auto& [name, ramp] :
       {std::pair<const char*, uint16_t>{"accel_ms", request.accel_ms},
        std::pair<const char*, uint16_t>{"decel_ms", request.decel_ms}}) {
    if (ramp > 0 && ramp < kMinRampMs) {
      return invalid(std::string(name) + " " + std::to_string(ramp) +
                     " is under 20 ms, the shortest ramp the servo runs (0: not given)");
    }
  }
  const uint32_t max_interval =
      request.multi_turn ? kMaxMultiTurnIntervalMs : std::numeric_limits<uint16_t>::max();
  if (!by_velocity && request.interval_ms > max_interval) {
    return invalid("interval_ms " + std::to_string(request.interval_ms) + " is above " +
                   std::to_string(max_interval) + " ms for a " +
                   (request.multi_turn ? "multi-turn" : "single-turn") + " move");
  }
  servo::MoveRamps ramps;
  ramps.accel_ms = std::max(request.accel_ms, kMinRampMs);
  ramps.decel_ms = std::max(request.decel_ms, kMinRampMs);
  ramps.power_mw = request.power_mw;
  if (with_ramps && !by_velocity && request.interval_ms < ramps.accel_ms + ramps.decel_ms) {
    return invalid("interval_ms " + std::to_string(request.interval_ms) +
                   " is shorter than accel + decel (" +
                   std::to_string(ramps.accel_ms + ramps.decel_ms) + " ms)");
  }

  // On the wire as the vendor SDK puts them: int(value * 10), truncated toward zero.
  const auto angle = static_cast<int32_t>(std::trunc(request.angle_deg * kDecidegreesPerDegree));
  const auto velocity =
      static_cast<uint16_t>(std::trunc(request.velocity_dps * kDecidegreesPerDegree));
  servo::MoveCommand& command = *out;
  command.id = request.id;
  command.angle_decidegrees = angle;
  command.interval_ms = request.interval_ms;
  command.velocity_decidegrees_per_s = velocity;
  command.ramps = ramps;
  if (by_velocity) {
    command.cmd = request.multi_turn ? Command::kMultiTurnMoveByVelocity : Command::kMoveByVelocity;
  } else if (with_ramps) {
    command.cmd = request.multi_turn ? Command::kMultiTurnMoveByInterval : Command::kMoveByInterval;
  } else {
    command.cmd = request.multi_turn ? Command::kMultiTurnMove : Command::kRotate;
  }
  return ok({});
}

}  // namespace serial_robot_driver::device
