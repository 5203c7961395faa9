#include "serial_robot_driver/devices/servo_bus/servo_move.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "servo_bus_text.h"

namespace serial_robot_driver::devices::servo_bus {

using namespace servo_text;  // NOLINT: the shared sentences of every servo operation

namespace {

// servo/move limits (vendor SDK and datasheet).
constexpr double kMaxSingleTurnDeg = 180.0;
constexpr double kMaxMultiTurnDeg = 368640.0;  // 1024 turns
constexpr double kMaxVelocityDps = 750.0;
constexpr double kMinVelocityDps = 0.1;  // the wire unit; anything less is sent as 0
constexpr uint16_t kMinRampMs = 20;      // the firmware's shortest ramp
constexpr uint32_t kMaxMultiTurnIntervalMs = 4096000;

const char* turnKind(const MoveRequest& request) {
  return request.multi_turn ? "multi-turn" : "single-turn";
}

/// The angle within the move's range and the velocity finite and not negative; "" if fine.
std::string angleProblem(const MoveRequest& request) {
  if (!std::isfinite(request.angle_deg)) return "angle_deg is not a finite number";
  if (!std::isfinite(request.velocity_dps)) return "velocity_dps is not a finite number";
  const double max_angle = request.multi_turn ? kMaxMultiTurnDeg : kMaxSingleTurnDeg;
  if (std::fabs(request.angle_deg) > max_angle) {
    return "angle_deg " + formatNumber(request.angle_deg) + " is out of range +-" +
           formatNumber(max_angle) + " deg for a " + turnKind(request) + " move";
  }
  if (request.velocity_dps < 0) {
    return "velocity_dps " + formatNumber(request.velocity_dps) +
           " is negative (0: not by velocity; the sign of the motion is the angle's)";
  }
  return {};
}

/// A velocity (when by velocity) the servo runs and the wire carries; "" if fine.
std::string velocityProblem(const MoveRequest& request) {
  if (request.velocity_dps > kMaxVelocityDps) {
    return "velocity_dps " + formatNumber(request.velocity_dps) + " is above the servo's 750 deg/s";
  }
  if (request.velocity_dps < kMinVelocityDps) {
    return "velocity_dps " + formatNumber(request.velocity_dps) +
           " is below 0.1 deg/s, the unit on the wire";
  }
  return {};
}

/// Given ramps the servo runs, and (by interval) an interval that fits the move and its ramps as
/// they will be sent; "" if fine.
std::string timingProblem(const MoveRequest& request, bool by_velocity, bool with_ramps,
                          const MoveRamps& ramps) {
  for (const auto& [name, ramp] :
       {std::pair<const char*, uint16_t>{"accel_ms", request.accel_ms},
        std::pair<const char*, uint16_t>{"decel_ms", request.decel_ms}}) {
    if (ramp > 0 && ramp < kMinRampMs) {
      return std::string(name) + " " + std::to_string(ramp) +
             " is under 20 ms, the shortest ramp the servo runs (0: not given)";
    }
  }
  if (by_velocity) return {};
  const uint32_t max_interval =
      request.multi_turn ? kMaxMultiTurnIntervalMs : std::numeric_limits<uint16_t>::max();
  if (request.interval_ms > max_interval) {
    return "interval_ms " + std::to_string(request.interval_ms) + " is above " +
           std::to_string(max_interval) + " ms for a " + turnKind(request) + " move";
  }
  if (with_ramps && request.interval_ms < ramps.accel_ms + ramps.decel_ms) {
    return "interval_ms " + std::to_string(request.interval_ms) +
           " is shorter than accel + decel (" + std::to_string(ramps.accel_ms + ramps.decel_ms) +
           " ms)";
  }
  return {};
}

/// The command that carries the move: by velocity, by interval with ramps, or the plain one.
Command moveCommandFor(bool multi_turn, bool by_velocity, bool with_ramps) {
  if (by_velocity) return multi_turn ? Command::kMultiTurnMoveByVelocity : Command::kMoveByVelocity;
  if (with_ramps) return multi_turn ? Command::kMultiTurnMoveByInterval : Command::kMoveByInterval;
  return multi_turn ? Command::kMultiTurnMove : Command::kRotate;
}

}  // namespace

ServoStatus toMoveCommand(const MoveRequest& request, MoveCommand* out) {
  const bool by_velocity = request.velocity_dps > 0;
  const bool with_ramps = by_velocity || request.accel_ms > 0 || request.decel_ms > 0;
  MoveRamps ramps;
  ramps.accel_ms = std::max(request.accel_ms, kMinRampMs);
  ramps.decel_ms = std::max(request.decel_ms, kMinRampMs);
  ramps.power_mw = request.power_mw;
  std::string problem = angleProblem(request);
  if (problem.empty() && by_velocity) problem = velocityProblem(request);
  if (problem.empty()) problem = timingProblem(request, by_velocity, with_ramps, ramps);
  if (!problem.empty()) return fail(ServoError::kInvalidArgument, problem);

  // On the wire as the vendor SDK puts them: int(value * 10), truncated toward zero.
  MoveCommand& command = *out;
  command.id = request.id;
  command.angle_decidegrees =
      static_cast<int32_t>(std::trunc(request.angle_deg * kDecidegreesPerDegree));
  command.interval_ms = request.interval_ms;
  command.velocity_decidegrees_per_s =
      static_cast<uint16_t>(std::trunc(request.velocity_dps * kDecidegreesPerDegree));
  command.ramps = ramps;
  command.cmd = moveCommandFor(request.multi_turn, by_velocity, with_ramps);
  return ok({});
}

}  // namespace serial_robot_driver::devices::servo_bus
